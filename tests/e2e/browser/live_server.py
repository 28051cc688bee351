"""What the live page's tests share (live_page_test.py): the server under test, plain-socket and
urllib requests, the check list, and the rule for a missing tool."""
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request

TOKEN_HEADER = "X-Prizma-Token"
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)
    return ok


def missing_tool(what):
    """Ends the test as tests/missing-tool does (it runs it): skipped (exit 77, ctest
    SKIP_RETURN_CODE) when `what` is missing, but failed with CI=true, where every test must run."""
    script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "missing-tool")
    sys.stdout.flush()
    os.execv(script, [script, what])


class Server:
    """prizma-relight FILE --serve -v on a free loopback port. Its first line of stdout is the page's
    whole URL, http://127.0.0.1:PORT/#token=SECRET; stderr (-v: the requests it refused) is read
    all along, so the server never blocks on a full pipe."""

    def __init__(self, relight, exr, save_dir, extra=()):
        self.proc = subprocess.Popen([relight, exr, "--serve", "-v", "--save-dir", save_dir, *extra],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.stderr = []
        self._reader = threading.Thread(target=self._drain, daemon=True)
        self._reader.start()
        line = self.proc.stdout.readline().strip()
        m = re.fullmatch(r"(http://127\.0\.0\.1:(\d+)/)#token=([0-9a-f]{32})", line)
        if not m:
            self.proc.kill()
            self.proc.wait()
            self._reader.join(timeout=5)
            raise RuntimeError("no URL from prizma-relight --serve: %r %s" % (line, "".join(self.stderr)))
        self.url, self.base, self.port, self.token = line, m[1], int(m[2]), m[3]
        self.stop_seconds = None

    def _drain(self):
        for line in self.proc.stderr:
            self.stderr.append(line)

    def refused(self):
        """The requests the server refused so far (its -v lines)."""
        return [l.strip() for l in list(self.stderr) if l.startswith("prizma-relight: refused ")]

    def stop(self, sig=signal.SIGTERM):
        """Sends `sig`; returns the exit code (None if it had not ended after 10 s) and records in
        stop_seconds how long it took to end."""
        start = time.monotonic()
        self.proc.send_signal(sig)
        try:
            rc = self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
            rc = None
        self.stop_seconds = time.monotonic() - start
        self._reader.join(timeout=5)
        return rc


def raw(port, data, timeout=10):
    """Sends raw bytes, returns the status code of the answer (0 when the server answered nothing)."""
    reply = b""
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
        try:
            s.sendall(data)
        except (ConnectionResetError, BrokenPipeError):
            pass  # the server may answer and close before reading everything
        try:
            while b"\r\n" not in reply:
                chunk = s.recv(65536)
                if not chunk:
                    break
                reply += chunk
        except (socket.timeout, ConnectionResetError, BrokenPipeError):
            pass
    first = reply.split(b"\r\n", 1)[0].split()
    return int(first[1]) if len(first) >= 2 and first[1].isdigit() else 0


def request_bytes(port, method, path, headers=None, host=None):
    """One HTTP/1.1 request (Connection: close; a POST declares its empty body)."""
    lines = ["%s %s HTTP/1.1" % (method, path), "Host: %s" % (host or "127.0.0.1:%d" % port), "Connection: close"]
    lines += ["%s: %s" % kv for kv in (headers or {}).items()]
    if method == "POST":
        lines.append("Content-Length: 0")
    return ("\r\n".join(lines) + "\r\n\r\n").encode()


def get(port, path, host=None, headers=None, method="GET"):
    return raw(port, request_bytes(port, method, path, headers, host))


def http(url, method="GET", token=None):
    headers = {TOKEN_HEADER: token} if token else {}
    req = urllib.request.Request(url, data=b"" if method == "POST" else None, method=method, headers=headers)
    try:
        with urllib.request.urlopen(req, timeout=60) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def snapshot(folder):
    """Every file of a folder (not below it): name → bytes, links as their target."""
    out = {}
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name)
        if os.path.islink(path):
            out[name] = "link to " + os.readlink(path)
        elif os.path.isfile(path):
            with open(path, "rb") as f:
                out[name] = f.read()
    return out
