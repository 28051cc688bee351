#!/usr/bin/env python3
"""prizma-relight -i in a real pseudo-terminal: a private tmux server of fixed size runs the shell,
keys go in with send-keys, the screen comes back with capture-pane. Checks line editing (Up recalls
the last command), Tab completion (a light name; a display name with a blank, quoted), history kept
across sessions in $XDG_STATE_HOME/prizma/relight_history, status, adapt, undo, show, the pixel-index
errors, and that a history that cannot be written, or is not libedit's, is only a warning. A fifth
session checks the keys and commands of issue 25 item 17: Ctrl-C cancels the line being typed (not
run, not in the history) and, on an empty line too, never ends the session; `clear` clears the
screen; `show kitty` and `show sixel` inside tmux say what tmux needs instead of reporting "drawn"
with nothing on the screen, and kitty goes through tmux's passthrough once it is allowed; Ctrl-D ends
the session.

Every wait polls the screen until the expected text is there, with a bound (TIMEOUT_S); the tmux
server is killed at the end whatever happened.

With --mri FILE a sixth session runs on that file (a render of data/scenes/mri.json): light names
completed from its layers (key, env), a light changed and switched off, a probe, a show.

With --fluor FILE (a small render of data/scenes/fluorescent_dye.json, bispectral channels) a seventh
session probes a pixel of the dyed sphere: the excitation-emission map of each light, and of one light
named after the coordinates, with its largest value as the digit 9.

usage: tmux_shell_test.py EXE SCENE.exr WORKDIR DATA_DIR [--transcript FILE] [--mri FILE] [--fluor FILE]
"""
import os
import re
import shlex
import shutil
import subprocess
import sys
import time

TIMEOUT_S = 30.0
PROMPT = "relight>"


class Failure(Exception):
    pass


class Pane:
    def __init__(self, server):
        self.server = server
        self.target = None
        self.sessions = 0
        self.socket = None

    def tmux(self, *args, check=True):
        r = subprocess.run(["tmux", "-L", self.server, "-u", "-f", "/dev/null", *args],
                           capture_output=True, text=True, timeout=TIMEOUT_S)
        if check and r.returncode != 0:
            raise Failure(f"tmux {' '.join(args)}: {r.stderr.strip()}")
        return r.stdout

    def start(self, command):
        # The command's exit status stays on the screen; the pane then waits to be killed.
        # A new tmux session each time (the old ones stay until the server is killed: killing the
        # last one would end the server while the next one is being started).
        wrapped = f"{command}; echo \"[exited $?]\"; sleep {int(TIMEOUT_S * 10)}"
        self.sessions += 1
        self.target = f"s{self.sessions}"
        self.tmux("new-session", "-d", "-s", self.target, "-x", "100", "-y", "40", "sh", "-c", wrapped)
        if not self.socket:
            self.socket = self.tmux("display-message", "-p", "#{socket_path}").strip()

    def kill(self):
        subprocess.run(["tmux", "-L", self.server, "kill-server"], capture_output=True, timeout=TIMEOUT_S)
        if self.socket and os.path.exists(self.socket):
            os.remove(self.socket)

    def screen(self):
        return self.tmux("capture-pane", "-p", "-J", "-S", "-5000", "-t", self.target)

    def visible(self):
        """The pane as it is on the screen now (no scrollback)."""
        return self.tmux("capture-pane", "-p", "-J", "-t", self.target)

    def lines(self):
        return [l.rstrip() for l in self.screen().split("\n")]

    def last_line(self):
        nonempty = [l for l in self.lines() if l]
        return nonempty[-1] if nonempty else ""

    def wait(self, what, predicate):
        deadline = time.monotonic() + TIMEOUT_S
        while time.monotonic() < deadline:
            text = self.screen()
            if predicate(text):
                return text
            time.sleep(0.05)
        raise Failure(f"timed out waiting for {what}; the screen:\n{self.screen()}")

    def wait_prompt(self, count=None):
        """The prompt is the last line, empty (count: the number of prompts on the screen so far)."""
        def ready(text):
            lines = [l.rstrip() for l in text.split("\n") if l.strip()]
            if not lines or lines[-1] != PROMPT:
                return False
            return count is None or sum(1 for l in lines if l.startswith(PROMPT)) >= count
        return self.wait(f"prompt #{count}", ready)

    def type(self, text):
        self.tmux("send-keys", "-t", self.target, "-l", text)

    def key(self, *keys):
        self.tmux("send-keys", "-t", self.target, *keys)

    def command(self, text):
        """Types a command at a fresh prompt and waits for the next prompt."""
        n = self.prompts()
        self.type(text)
        self.key("Enter")
        return self.wait_prompt(n + 1)

    def prompts(self):
        return sum(1 for l in self.lines() if l.startswith(PROMPT))


def expect(cond, message, screen=""):
    if not cond:
        raise Failure(message + ("\nthe screen:\n" + screen if screen else ""))


def session_command(exe, scene, env):
    assigns = " ".join(f"{k}={shlex.quote(v)}" for k, v in env.items())
    return f"env -u PRIZMA_TERMINAL_IMAGES -u KITTY_WINDOW_ID {assigns} {shlex.quote(exe)} {shlex.quote(scene)} -i"


def tmux_version(pane):
    m = re.search(r"([0-9]+)\.([0-9]+)", subprocess.run(["tmux", "-V"], capture_output=True, text=True).stdout)
    return (int(m[1]), int(m[2])) if m else (0, 0)


def session_keys(pane, exe, scene, env, history):
    """Session 5 (issue 25 item 17): Ctrl-C, clear, show inside tmux, Ctrl-D."""
    pane.start(session_command(exe, scene, env))
    pane.wait_prompt(1)
    # Ctrl-C cancels the line being typed: nothing runs, a new prompt, as in bash.
    pane.type("exposure 3")
    pane.wait("the typed line", lambda s: pane.last_line() == f"{PROMPT} exposure 3")
    pane.key("C-c")
    screen = pane.wait_prompt(2)
    expect(f"{PROMPT} exposure 3^C" in screen, "Ctrl-C did not cancel the line with ^C", screen)
    # … and on an empty line it does not end the session either.
    pane.key("C-c")
    screen = pane.wait_prompt(3)
    expect(f"{PROMPT} ^C" in screen and "[exited" not in screen, "Ctrl-C on an empty line ended the session", screen)
    screen = pane.command("status")
    expect("exposure    0 EV" in screen and "undo        0 levels" in screen,
           "the cancelled line ran (status after Ctrl-C)", screen)
    with open(history, encoding="utf-8", errors="replace") as f:
        expect("exposure 3" not in f.read(), "the cancelled line went into the history")
    # clear: only the prompt is left on the screen (the output before it is gone from view).
    pane.type("clear")
    pane.key("Enter")
    pane.wait("the screen cleared", lambda s: [l.rstrip() for l in pane.visible().split("\n") if l.strip()] == [PROMPT])
    # show kitty / sixel inside tmux: not "drawn" with nothing on the screen, but what tmux needs.
    screen = pane.command("show kitty")
    tail = screen[screen.rfind(f"{PROMPT} show kitty"):]
    expect("error: show kitty: inside tmux" in tail and "tmux set -g allow-passthrough on" in tail and "drawn" not in tail,
           "show kitty inside tmux (passthrough off) did not say what to do", tail)
    if tmux_version(pane) < (3, 4):  # no sixel in tmux before 3.4
        screen = pane.command("show sixel")
        tail = screen[screen.rfind(f"{PROMPT} show sixel"):]
        expect("error: show sixel: this tmux draws no sixel images" in tail and "drawn" not in tail,
               "show sixel inside a tmux without sixel did not say so", tail)
    pane.tmux("set-option", "-g", "allow-passthrough", "on")
    screen = pane.command("show kitty")
    tail = screen[screen.rfind(f"{PROMPT} show kitty"):]
    expect("through tmux's passthrough" in tail and re.search(r"drawn in [0-9.]+ ms", tail) and "error" not in tail,
           "show kitty with passthrough allowed was not drawn through it", tail)
    pane.tmux("set-option", "-g", "allow-passthrough", "off")
    # Ctrl-D on an empty line ends the session (exit 0).
    pane.key("C-d")
    pane.wait("Ctrl-D to end the session", lambda s: "[exited 0]" in s)


def main():
    args = sys.argv[1:]
    transcript = None
    if "--transcript" in args:
        i = args.index("--transcript")
        transcript = args[i + 1]
        del args[i:i + 2]
    mri = None
    if "--mri" in args:
        i = args.index("--mri")
        mri = os.path.abspath(args[i + 1])
        del args[i:i + 2]
    fluor = None
    if "--fluor" in args:
        i = args.index("--fluor")
        fluor = os.path.abspath(args[i + 1])
        del args[i:i + 2]
    exe, scene, work, data = args
    shutil.rmtree(work, ignore_errors=True)
    state = os.path.join(work, "state")
    home = os.path.join(work, "home")
    os.makedirs(home)
    env = {"XDG_STATE_HOME": state, "HOME": home, "PRIZMA_DATA_DIR": data, "LANG": "C.UTF-8", "TERM": "screen"}
    history = os.path.join(state, "prizma", "relight_history")

    server = f"shell-test-{os.getpid()}"
    pane = Pane(server)
    try:
        os.chdir(work)
        # Session 1.
        pane.start(session_command(exe, scene, env))
        pane.wait_prompt(1)
        # A command, then Up and Enter: it runs twice.
        screen = pane.command("probe 1 1")
        expect(screen.count("\n  XYZ ") == 1, "probe did not run", screen)
        pane.key("Up")
        pane.wait("Up to recall the command", lambda s: pane.last_line() == f"{PROMPT} probe 1 1")
        pane.key("Enter")
        screen = pane.wait_prompt(3)
        outputs = [l for l in screen.split("\n") if l.rstrip() == "probe 1 1"]
        expect(len(outputs) == 2, f"probe ran {len(outputs)} times, expected 2", screen)
        expect("^[[A" not in screen and "unknown command" not in screen, "Up was not taken as a key", screen)
        # Tab completes a light name; the command then runs.
        pane.type("light k")
        pane.key("Tab")
        pane.wait("light name completed", lambda s: pane.last_line() == f"{PROMPT} light key")
        n = pane.prompts()
        pane.type("A")
        pane.key("Enter")
        screen = pane.wait_prompt(n + 1)
        expect("error" not in screen, "light key A failed", screen)
        # Tab completes a display name with a blank, quoted, and the quoted name works.
        pane.type("display Di")
        pane.key("Tab")
        pane.wait("display completed in quotes", lambda s: pane.last_line() == f'{PROMPT} display "Display P3"')
        n = pane.prompts()
        pane.key("Enter")
        pane.wait_prompt(n + 1)
        pane.command("adapt on")
        screen = pane.command("status")
        for want in ["light       key = A (default D65)", "display     Display P3", "adaptation  on",
                     "undo        3 levels"]:
            expect(want in screen, f"status does not show '{want}'", screen)
        pane.command("undo")
        pane.command("undo")
        screen = pane.command("status")
        tail = screen[screen.rfind("file        "):]
        for want in ["display     sRGB", "adaptation  off", "light       key = A", "undo        1 level"]:
            expect(want in tail, f"status after two undos does not show '{want}'", tail)
        # The pixel index of issue 11.
        screen = pane.command("compare 0 0 99999999999 0")
        expect('error: compare X2: 99999999999 is outside the' in screen, "no clear error for a huge index", screen)
        # show: tmux answers the device-attributes query without sixel: half blocks, no hang.
        screen = pane.command("show")
        expect("\u2580" in screen, "show drew no half blocks", screen)
        expect(screen.count("relit in ") >= 6, "changes did not print their relight time", screen)
        expect(re.search(r"drawn in [0-9.]+ ms \(last relight [0-9.]+ ms\)", screen) is not None,
               "show did not print its time", screen)
        pane.type("quit")
        pane.key("Enter")
        pane.wait("the first session to end", lambda s: "[exited 0]" in s)
        if transcript:
            with open(transcript, "w") as f:
                f.write(pane.screen())

        # The history file holds the session's lines.
        expect(os.path.isfile(history), f"no history file at {history}")
        with open(history, encoding="utf-8", errors="replace") as f:
            saved = f.read()
        expect("probe" in saved and "quit" in saved, f"history file lacks the commands:\n{saved}")

        # Session 2: Up recalls the first session's commands, newest first.
        pane.start(session_command(exe, scene, env))
        pane.wait_prompt(1)
        pane.key("Up")
        pane.wait("the last command of session 1", lambda s: pane.last_line() == f"{PROMPT} quit")
        pane.key("Up")
        pane.wait("the one before", lambda s: pane.last_line() == f"{PROMPT} show")
        pane.key("Up")
        pane.wait("and the one before", lambda s: pane.last_line() == f"{PROMPT} compare 0 0 99999999999 0")
        pane.key("C-u")
        pane.wait("the line cleared", lambda s: pane.last_line() == PROMPT)
        pane.type("quit")
        pane.key("Enter")
        pane.wait("the second session to end", lambda s: "[exited 0]" in s)

        # Session 3: a history that cannot be written is a warning; the session goes on.
        bad = dict(env, XDG_STATE_HOME="/proc/self/prizma-cannot-be-here")
        pane.start(session_command(exe, scene, bad))
        pane.wait_prompt(1)
        screen = pane.command("status")
        expect("warning:" in screen and "history not saved" in screen, "no warning for an unwritable history", screen)
        expect("exposure    0 EV" in screen, "status did not run after the warning", screen)
        pane.type("quit")
        pane.key("Enter")
        pane.wait("the third session to end", lambda s: "[exited 0]" in s)

        # Session 4: a history file that is not libedit's is neither read nor overwritten.
        foreign_state = os.path.join(work, "foreign")
        os.makedirs(os.path.join(foreign_state, "prizma"))
        foreign = os.path.join(foreign_state, "prizma", "relight_history")
        with open(foreign, "w") as f:
            f.write("my own notes\n")
        pane.start(session_command(exe, scene, dict(env, XDG_STATE_HOME=foreign_state)))
        screen = pane.wait_prompt(1)
        expect("history not loaded" in screen, "no warning for a foreign history file", screen)
        pane.command("exposure 1")
        pane.type("quit")
        pane.key("Enter")
        pane.wait("the fourth session to end", lambda s: "[exited 0]" in s)
        with open(foreign) as f:
            expect(f.read() == "my own notes\n", "the foreign history file was overwritten")
        session_keys(pane, exe, scene, env, history)
        if mri:
            # Session 6: the MRI render, through the same keys.
            pane.start(session_command(exe, mri, env))
            screen = pane.wait_prompt(1)
            expect("relit in " in screen and "error" not in screen, "the MRI file did not open", screen)
            pane.type("light e")
            pane.key("Tab")
            pane.wait("the MRI's light name completed", lambda s: pane.last_line() == f"{PROMPT} light env")
            pane.type(" off")
            pane.key("Enter")
            pane.wait_prompt(2)
            pane.command("light key blackbody:3200K")
            screen = pane.command("status")
            for want in ["light       key = blackbody:3200K (default D65)", "light       env = off (default D65*0.3)"]:
                expect(want in screen, f"MRI status does not show '{want}'", screen)
            screen = pane.command("probe 24 24")
            expect(re.search(r"probed in [0-9.]+ ms", screen) is not None, "MRI probe printed no time", screen)
            screen = pane.command("show")
            expect("\u2580" in screen and "error" not in screen, "show drew no MRI image", screen)
            pane.type("quit")
            pane.key("Enter")
            pane.wait("the MRI session to end", lambda s: "[exited 0]" in s)
        if fluor:
            # Session 7: a fluorescent render, the pixel probe's excitation-emission map.
            pane.start(session_command(exe, fluor, env))
            screen = pane.wait_prompt(1)
            expect("relit in " in screen and "error" not in screen, "the fluorescent file did not open", screen)
            pane.command("light key LED-V1")
            screen = pane.command("probe 8 8")
            for light in ("key", "sky"):
                expect(f"excitation–emission {light}: M[out][in] as 0–9 of its largest" in screen,
                       f"probe printed no excitation-emission map for light {light}", screen)
            expect(re.search(r"out\\in( +[0-9]{3})+\n", screen) is not None, "the map has no in-bin header", screen)
            rows = re.findall(r"^ +[0-9]{3}(?:   [0-9.\\ ])+$", screen, flags=re.M)
            expect(len(rows) >= 2 and any("9" in r for r in rows), "the map has no rows with its largest value 9", screen)
            n = pane.prompts()
            pane.type("probe 8 8 s")
            pane.key("Tab")
            pane.wait("a light name completed after probe X Y", lambda s: pane.last_line() == f"{PROMPT} probe 8 8 sky")
            pane.key("Enter")
            screen = pane.wait_prompt(n + 1)
            tail = screen[screen.rfind("probe 8 8 sky"):]
            expect("excitation–emission sky" in tail and "excitation–emission key" not in tail,
                   "probe X Y LIGHT did not restrict the map to that light", tail)
            pane.type("quit")
            pane.key("Enter")
            pane.wait("the fluorescent session to end", lambda s: "[exited 0]" in s)
        print("terminal session test passed")
        return 0
    except Failure as e:
        print(f"FAILED: {e}", file=sys.stderr)
        return 1
    finally:
        pane.kill()


if __name__ == "__main__":
    sys.exit(main())
