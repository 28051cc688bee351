"""prizma.serve: the live relighting page (prizma-relight --serve) for an image in memory or a file.

The server is the installed ``prizma-relight FILE --serve`` itself, run as a child process, not a
binding of its C++ server: the tool installs its own SIGINT/SIGTERM handlers and threads for as long
as it serves, which inside the interpreter would fight Python's signal handling (Ctrl-C in a
notebook) and keep a server alive in a process that cannot stop it cleanly; a child process is
stopped with one signal, whatever the interpreter is doing, and serves exactly what the tool serves
(docs/relight.md, "Live page"). An image in memory goes to the tool as a file: ``image.exr`` in a
private temporary folder (mode 0700; the file 0600), removed when the server stops.
"""

import atexit as _atexit
import codecs as _codecs
import os as _os
import re as _re
import selectors as _selectors
import shutil as _shutil
import signal as _signal
import subprocess as _subprocess
import sys as _sys
import tempfile as _tempfile
import threading as _threading
import weakref as _weakref

from . import _prizma
from ._prizma import InputError, RuntimeFailure

_STOP_SECONDS = 10  # how long stop() waits for the tool to end after SIGTERM before killing it
_running = _weakref.WeakSet()  # servers stopped at interpreter exit


def _refusal(input, reason):
    """InputError as the package makes them: "input: reason", with .input and .reason."""
    e = InputError(f"{input}: {reason}")
    e.input, e.reason = input, reason
    return e


def _error_from_tool(code, stderr):
    """The exception a failed start of prizma-relight stands for: its one-line message after
    "prizma-relight: error: ", InputError (exit 2, with .input and .reason) or RuntimeFailure."""
    lines = [line for line in stderr.splitlines() if line.strip()]
    message = lines[-1] if lines else f"prizma-relight --serve ended with status {code} before serving"
    message = message.split("prizma-relight: error: ", 1)[-1]
    if code == 2:
        input, _, reason = message.partition(": ")
        return _refusal(input, reason)
    return RuntimeFailure(message)


def _tool_arguments(lights, exposure, display):
    """prizma-relight's options for the page's starting state (lights as spec strings only: the tool
    reads its lights from the command line)."""
    args = ["--exposure", repr(float(exposure)), "--display", str(display)]
    if lights is None:
        return args
    if isinstance(lights, str):
        return args + ["--light", lights]
    if isinstance(lights, dict):
        for name, spec in lights.items():
            if spec is not None and not isinstance(spec, str):
                raise _refusal(f'lights["{name}"]', "prizma.serve takes spec strings (a measured spectrum: a csv: "
                                                    "file, docs/spectra.md)")
            args += ["--light", f"{name}={'off' if spec is None else spec}"]
        return args
    raise _refusal("lights", "prizma.serve takes None, a spec string, or a dict {name: spec string or None}")


class Server:
    """A running live page: ``url`` (with its secret token: whoever has it can use the page),
    ``port``, ``stop()``. A context manager: leaving the ``with`` block stops it. Stopped, too, when
    the object is garbage-collected or the interpreter exits."""

    def __init__(self, command, folder):
        self._folder = folder
        self._reader = None  # the thread that shows the tool's stderr while it serves
        self.url = None
        self.port = None
        # Unbuffered bytes: both pipes are read through select until the URL line arrives, so what
        # the tool wrote on stderr before its URL (a --bind warning) is read, and shown, before
        # serve() returns; a pipe the tool fills before serving never blocks it.
        self._proc = _subprocess.Popen(command, stdin=_subprocess.DEVNULL, stdout=_subprocess.PIPE,
                                       stderr=_subprocess.PIPE, bufsize=0)
        out, err = self._read_until_url()
        line = out.decode(errors="replace").strip()
        m = _re.fullmatch(r"http://[^/]*:(\d+)/#token=[0-9a-f]+", line)
        if not m:  # the tool refused (its stdout closed as it ended), or said something unexpected
            try:
                code = self._proc.wait(timeout=_STOP_SECONDS)
            except _subprocess.TimeoutExpired:
                self._proc.kill()
                code = self._proc.wait()
            err += self._proc.stderr.read()
            self._proc.stdout.close()
            self._proc.stderr.close()
            self._remove_folder()
            raise _error_from_tool(code, err.decode(errors="replace") or line)
        self.url, self.port = line, int(m[1])
        _sys.stderr.write(err.decode(errors="replace"))  # shown as the tool shows it, before the URL
        self._reader = _threading.Thread(target=self._relay_stderr, daemon=True)
        self._reader.start()
        _running.add(self)

    def _read_until_url(self):
        """The tool's stdout up to its first line (the URL; less when it ended) and all it wrote on
        stderr until then: the tool writes its warnings before the URL, so they are in the pipe by
        the time the URL is, and are drained here without waiting."""
        out, err = b"", b""
        fds = {self._proc.stdout.fileno(): "out", self._proc.stderr.fileno(): "err"}
        with _selectors.DefaultSelector() as sel:
            for fd in fds:
                sel.register(fd, _selectors.EVENT_READ)
            while b"\n" not in out and sel.get_map():
                for key, _ in sel.select():
                    chunk = _os.read(key.fd, 65536)
                    if not chunk:
                        sel.unregister(key.fd)
                    elif fds[key.fd] == "out":
                        out += chunk
                    else:
                        err += chunk
            err_fd = self._proc.stderr.fileno()
            while err_fd in sel.get_map() and sel.select(timeout=0):  # what is already there
                chunk = _os.read(err_fd, 65536)
                if not chunk:
                    sel.unregister(err_fd)
                err += chunk
        return out.split(b"\n", 1)[0], err

    def _relay_stderr(self):
        """Reads the tool's stderr for as long as it serves (a full pipe would block it) and shows
        it (warnings, refusals), as the tool shows them."""
        fd = self._proc.stderr.fileno()
        text = _codecs.getincrementaldecoder("utf-8")(errors="replace")  # a character split by read()
        while True:
            chunk = _os.read(fd, 65536)
            if not chunk:
                break
            _sys.stderr.write(text.decode(chunk))

    def _remove_folder(self):
        if self._folder is not None:
            _shutil.rmtree(self._folder, ignore_errors=True)
            self._folder = None

    @property
    def running(self):
        """True until the server has been stopped (or the tool ended by itself)."""
        return self._proc.poll() is None

    def stop(self):
        """Stops the server (SIGTERM, as Ctrl-C stops prizma-relight --serve; killed after 10 s) and
        removes the temporary file. Returns the tool's exit status; calling it again does nothing."""
        if self._proc.poll() is None:
            self._proc.send_signal(_signal.SIGTERM)
            try:
                self._proc.wait(timeout=_STOP_SECONDS)
            except _subprocess.TimeoutExpired:
                self._proc.kill()
                self._proc.wait()
        if self._reader is not None:
            self._reader.join(timeout=_STOP_SECONDS)
        self._proc.stdout.close()
        if self._reader is None or not self._reader.is_alive():
            self._proc.stderr.close()
        self._remove_folder()
        _running.discard(self)
        return self._proc.returncode

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()

    def __del__(self):
        if getattr(self, "_proc", None) is not None:
            self.stop()

    def __repr__(self):
        return f"<prizma.Server {self.url} {'running' if self.running else 'stopped'}>"

    def _repr_html_(self):
        """Jupyter: a link that opens the page in a new tab."""
        return f'<a href="{self.url}" target="_blank" rel="noopener">prizma live page: {self.url}</a>'


@_atexit.register
def _stop_all():
    for server in list(_running):
        server.stop()


def serve(image, path_of, write, port=0, bind="127.0.0.1", save_dir=None, lights=None, exposure=0.0,
          display="sRGB"):
    """prizma.serve's body (its docstring is in __init__.py); path_of and write are the package's
    path check and writer."""
    tool = _prizma.relight_tool_path()
    if not tool:
        raise RuntimeFailure("prizma.serve: prizma-relight not found (installed with the module in bin/, "
                             "or built beside it): install the tools (scripts/install)")
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise _refusal("port", f"must be an integer within 0 … 65535 (got {port!r})")
    options = ["--serve", "--port", str(port), "--bind", str(bind),
               "--save-dir", path_of(save_dir if save_dir is not None else _os.getcwd(), "save_dir")]
    options += _tool_arguments(lights, exposure, display)
    folder = None
    if isinstance(image, (str, bytes, _os.PathLike)):
        source = path_of(image, "image")
    else:
        folder = _tempfile.mkdtemp(prefix="prizma-serve-")  # mode 0700: only this user looks in
        source = _os.path.join(folder, "image.exr")
        try:
            write(source, image)
            _os.chmod(source, 0o600)
        except BaseException:
            _shutil.rmtree(folder, ignore_errors=True)
            raise
    try:
        server = Server([tool, source, *options], folder)
    except BaseException:  # the tool refused the image or options, or could not be started
        if folder is not None:
            _shutil.rmtree(folder, ignore_errors=True)
        raise
    print(server.url, flush=True)  # as prizma-relight --serve prints it
    return server
