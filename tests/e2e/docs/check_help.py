#!/usr/bin/env python3
"""The tools' help as a user meets it, on the installed tree (issue 25 item 18; ctest docs.help):

- `--help` of each tool has examples, and every option an example uses is one the tool (or the
  subcommand the example runs) takes; whole-number options are named INT, files PATH (not TEXT);
- `man TOOL` shows the installed page (share/man/man1) with its EXAMPLES, through the real man;
- bash completion (share/bash-completion/completions) in a real bash in a tmux pane: Tab completes
  an option name, an option's fixed values and a subcommand.

usage: check_help.py PREFIX WORK
"""
import os
import re
import shlex
import subprocess
import sys
import time

TOOLS = {"prizma-render": ["merge", "inspect", "denoise"], "prizma-relight": ["compress"],
         "prizma-metamer": ["metamer", "light", "delta-e", "weights", "tabulate"]}
failures = []


def claim(ok, text):
    print(("ok    " if ok else "FAIL  ") + text)
    if not ok:
        failures.append(text)


def run(args, env):
    return subprocess.run(args, capture_output=True, text=True, timeout=60, env=env)


def option_names(help_text):
    names = set()
    for line in help_text.split("\n"):
        m = re.match(r"^  (-[\w-]+(?:,-[\w-]+)*)", line)
        if m:
            names.update(m.group(1).split(","))
    return names


def check_help(tool, env):
    text = run([tool, "--help"], env).stdout
    claim("Examples:" in text, tool + " --help has examples")
    examples = [l.strip() for l in text.split("Examples:", 1)[-1].split("\n") if l.startswith("  " + tool)]
    claim(len(examples) >= 3, "%s --help: %d examples" % (tool, len(examples)))
    own = option_names(text)
    subs = {s: option_names(run([tool, s, "--help"], env).stdout) for s in TOOLS[tool]}
    for ex in examples:
        words = shlex.split(ex.split("  (")[0])[1:]
        sub = words[0] if words and words[0] in subs else None
        known = subs[sub] | (own if tool == "prizma-metamer" else set()) if sub else own
        unknown = [w for w in words if w.startswith("-") and not re.match(r"^-\d", w) and w not in known]
        claim(not unknown, "%s example %r: options %s" % (tool, ex, unknown or "all known"))
    for line in text.split("\n"):
        m = re.match(r"^  (?:-\w,)?(--spp|--width|--height|--seed|--output|--batch) (\S+)", line)
        if m:
            want = "INT" if m.group(1) in ("--spp", "--width", "--height", "--seed") else "PATH"
            claim(m.group(2).startswith(want), "%s %s is named %s (got %s)" % (tool, m.group(1), want, m.group(2)))


def check_man(prefix, tool, env):
    page = os.path.join(prefix, "share", "man", "man1", tool + ".1")
    claim(os.path.isfile(page), "installed " + os.path.relpath(page, prefix))
    # As a user reads it: man finds the page from PATH's bin/../share/man.
    r = run(["man", "-P", "cat", tool], dict(env, MANWIDTH="100", MANPATH=os.path.join(prefix, "share", "man")))
    text = re.sub(r".\x08", "", r.stdout)
    claim(r.returncode == 0 and "EXAMPLES" in text and "SUBCOMMANDS" in text and tool in text,
          "man %s shows the page with EXAMPLES and SUBCOMMANDS (exit %d)" % (tool, r.returncode))


class Pane:
    """bash in a private tmux server: keys in with send-keys, the screen back with capture-pane."""

    def __init__(self, env):
        self.server = "prizma-help-%d" % os.getpid()
        self.env = env

    def tmux(self, *args):
        return subprocess.run(["tmux", "-L", self.server, "-f", "/dev/null", *args], capture_output=True,
                              text=True, timeout=30, env=self.env).stdout

    def wait_for(self, pattern):
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            screen = self.tmux("capture-pane", "-p", "-J")
            if re.search(pattern, screen):
                return screen
            time.sleep(0.1)
        return self.tmux("capture-pane", "-p", "-J")


def check_completion(prefix, work, env):
    completions = os.path.join(prefix, "share", "bash-completion", "completions")
    for tool in TOOLS:
        claim(os.path.isfile(os.path.join(completions, tool)), "installed share/bash-completion/completions/" + tool)
    open(os.path.join(work, "scene_a.json"), "w").close()
    pane = Pane(env)
    rc = os.path.join(work, "bashrc")
    with open(rc, "w") as f:
        f.write("PS1='$ '\n" + "".join(". %s\n" % shlex.quote(os.path.join(completions, t)) for t in TOOLS))
    try:
        pane.tmux("new-session", "-d", "-x", "120", "-y", "30", "-c", work, "bash", "--noprofile", "--rcfile", rc, "-i")
        pane.wait_for(r"(?m)^\$")
        for keys, want, what in (("prizma-render --wav\t", r"prizma-render --wavelength-sampling ", "an option name"),
                                 ("spectral-t\t", r"--wavelength-sampling spectral-tracking ", "an option's value"),
                                 ("scene_\t", r"spectral-tracking scene_a\.json", "a file name")):
            pane.tmux("send-keys", "-l", keys)
            screen = pane.wait_for(want)
            claim(re.search(want, screen) is not None, "bash completes %s: %r → %s" % (what, keys, screen.strip().split("\n")[-1]))
        pane.tmux("send-keys", "C-c")
        # Keys sent while bash is still handling the interrupt are thrown away with the line: type
        # only once the fresh prompt is on screen (under load this took longer than the keys).
        pane.wait_for(r"\^C\n\$ *\n")
        pane.tmux("send-keys", "-l", "prizma-relight com\t")
        screen = pane.wait_for(r"prizma-relight compress ")
        claim("prizma-relight compress " in screen, "bash completes a subcommand: %r" % screen.strip().split("\n")[-1])
    finally:
        subprocess.run(["tmux", "-L", pane.server, "kill-server"], capture_output=True, timeout=30)


def main():
    prefix, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    os.makedirs(work, exist_ok=True)
    env = dict(os.environ, PATH=os.path.join(prefix, "bin") + ":/usr/bin:/bin", HOME=work, LANG="C.UTF-8")
    env.pop("PRIZMA_DATA_DIR", None)
    for tool in TOOLS:
        check_help(tool, env)
        check_man(prefix, tool, env)
    check_completion(prefix, work, env)
    if failures:
        sys.exit("%d help check(s) failed" % len(failures))


if __name__ == "__main__":
    main()
