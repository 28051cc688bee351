#!/usr/bin/env python3
"""Man pages and bash completion of the Prizma tools, made at build time from their --help texts
(issue 25 item 18), so that neither can drift from the options the tools take.

  make_tool_docs.py man EXE NAME SUMMARY OUT.1 [SUBCOMMAND...]
      help2man on EXE (its --help and --version), with a SUBCOMMANDS section holding each
      subcommand's --help.
  make_tool_docs.py completion EXE NAME OUT [SUBCOMMAND...]
      a bash completion script for NAME (bash-completion loads completions/NAME when NAME is first
      completed): its subcommands, each (sub)command's options, the values of options with a fixed
      set ({a,b} in --help), file names for PATH options and for the positional files.
"""
import os
import re
import subprocess
import sys
import tempfile

# "  -o,--output PATH REQUIRED   output …", "  --cmf TEXT=1931   …", "  --sampler TEXT:{independent,sobol}"
OPTION = re.compile(r"^  (-[\w-]+(?:,-[\w-]+)*)(?: (\S+))?")


def help_text(exe, args):
    r = subprocess.run([exe, *args, "--help"], capture_output=True, text=True, timeout=60,
                       env=dict(os.environ, COLUMNS="100"))
    if r.returncode != 0:
        sys.exit("%s %s --help failed (%d): %s" % (exe, " ".join(args), r.returncode, r.stderr))
    return r.stdout


def options(text):
    """[(names, value type or '')] of the Options section of a CLI11 help text."""
    out = []
    section = ""
    for line in text.split("\n"):
        if line and not line.startswith(" "):
            section = line
            continue
        if not section.startswith("Options"):
            continue
        m = OPTION.match(line)
        if m:
            out.append((m.group(1).split(","), m.group(2) or ""))
    return out


def roff(lines):
    """Help text as man page text: indented lines (usage forms, examples) kept as they are (.nf),
    the others as paragraphs."""
    out, verbatim = [], False
    for line in lines:
        indented = line.startswith("  ")
        if indented != verbatim:
            out.append(".nf" if indented else ".fi")
            verbatim = indented
        out.append(line.replace("\\", "\\\\").replace("-", "\\-") if indented else line.replace("\\", "\\\\"))
    if verbatim:
        out.append(".fi")
    return out


def man(exe, name, summary, out, subcommands):
    # The description (before "Usage:") and the examples (from "Examples:" on) as they are in --help:
    # help2man would fill their indented lines into one paragraph.
    text = help_text(exe, []).rstrip("\n").split("\n")
    usage = next(i for i, l in enumerate(text) if l.startswith("Usage:"))
    examples = next((i for i, l in enumerate(text) if l.startswith("Examples:")), len(text))
    options_at = next((i for i, l in enumerate(text) if l.startswith("Options:")), usage + 1)
    include = ["[=DESCRIPTION]"] + roff(text[:usage] + text[usage + 1:options_at])  # and the positionals
    if examples < len(text):
        include += ["[=EXAMPLES]"] + roff(text[examples + 1:])
    include += ["[SUBCOMMANDS]"] if subcommands else []
    for sub in subcommands:
        include += [".SS %s %s" % (name, sub), ".nf", help_text(exe, [sub]).replace("\\", "\\\\").rstrip(), ".fi"]
    with tempfile.NamedTemporaryFile("w", suffix=".h2m", delete=False) as f:
        f.write("\n".join(include) + "\n")
        include_path = f.name
    try:
        cmd = ["help2man", "--no-info", "--no-discard-stderr", "--section=1", "--name=" + summary,
               "--output=" + out, "--include=" + include_path, exe]
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=120, env=dict(os.environ, COLUMNS="100"))
        if r.returncode != 0:
            sys.exit("help2man failed for %s: %s" % (name, r.stderr))
    finally:
        os.unlink(include_path)
    # help2man names the program after the executable's path; the page is the command's.
    with open(out, encoding="utf-8") as f:
        page = f.read()
    with open(out, "w", encoding="utf-8") as f:
        f.write(page.replace(exe, name))


def shell_words(words):
    return " ".join(w.replace("'", "") for w in words)


def completion(exe, name, out, subcommands):
    fn = "_" + re.sub(r"[^A-Za-z0-9_]", "_", name)
    cases, option_lists = [], {}
    for sub in [""] + subcommands:
        opts = options(help_text(exe, [sub] if sub else []))
        option_lists[sub] = [n for names, _ in opts for n in names]
        for names, kind in opts:
            choice = re.search(r"\{([^}]*)\}", kind)
            pattern = "|".join("%s:%s" % (sub, n) for n in names)
            if choice:
                cases.append("    %s) COMPREPLY=($(compgen -W '%s' -- \"$cur\")); return ;;" %
                             (pattern, shell_words(choice.group(1).split(","))))
            elif kind.startswith("PATH"):
                cases.append("    %s) compopt -o filenames 2>/dev/null; COMPREPLY=($(compgen -f -- \"$cur\")); return ;;" % pattern)
            elif kind:
                cases.append("    %s) return ;;  # %s: nothing to offer" % (pattern, kind))
    lists = "\n".join("    %s) words='%s' ;;" % (sub or "''", shell_words(option_lists[sub])) for sub in option_lists)
    script = """# bash completion of %(name)s, made from its --help by cmake/make_tool_docs.py (do not edit)
%(fn)s() {
  local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD-1]} sub='' w words
  for w in "${COMP_WORDS[@]:1:COMP_CWORD-1}"; do
    case "$w" in %(subs)s) sub=$w ;; esac
  done
  case "$sub:$prev" in
%(cases)s
  esac
  case "$sub" in
%(lists)s
  esac
  if [[ $cur == -* ]]; then
    COMPREPLY=($(compgen -W "$words" -- "$cur"))
  else
    compopt -o filenames 2>/dev/null
    COMPREPLY=($([[ -z $sub ]] && compgen -W '%(sublist)s' -- "$cur"; compgen -f -- "$cur"))
  fi
}
complete -F %(fn)s %(name)s
""" % {"name": name, "fn": fn, "subs": "|".join(subcommands) or "''", "cases": "\n".join(cases), "lists": lists,
       "sublist": " ".join(subcommands)}
    with open(out, "w", encoding="utf-8") as f:
        f.write(script)


def main():
    if len(sys.argv) >= 6 and sys.argv[1] == "man":
        man(sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5], sys.argv[6:])
    elif len(sys.argv) >= 5 and sys.argv[1] == "completion":
        completion(sys.argv[2], sys.argv[3], sys.argv[4], sys.argv[5:])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
