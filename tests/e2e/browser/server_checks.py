"""live_page_test.py server: prizma-relight --serve through plain sockets and urllib.

Bad requests (path traversal, long URLs, malformed requests, foreign Host, save outside the folder,
csv: specs) each get a 4xx and the server stays up; every /api route refuses (403) a request without
the run's secret, with a wrong one, or from another page (Origin, Sec-Fetch-Site); Save never writes
the served file (also through a hard link), never through a symbolic link; a second server on the
same port is refused (exit 2); 64 idle or slow (slowloris) connections leave the page answering, and
SIGINT / SIGTERM end the server within 1 s even with them open.
"""
import json
import os
import secrets
import shutil
import signal
import socket
import subprocess
import tempfile
import threading
import time

from live_server import Server, TOKEN_HEADER, check, get, http, raw, request_bytes, snapshot

# Every /api route, with parameters that are valid for two.exr (64×48, 2 lights, 16 bins).
API_ROUTES = [
    ("GET", "/api/info"),
    ("GET", "/api/transport?light=0&group=0"),
    ("GET", "/api/weights?exposure=1"),
    ("GET", "/api/spectra"),
    ("GET", "/api/display?name=sRGB"),
    ("GET", "/api/probe?x=1&y=1"),
    ("GET", "/api/compare?x1=0&y1=0&x2=1&y2=1"),
    ("POST", "/api/save?file=forged.png"),
]


def check_bad_requests(srv):
    p = srv.port
    auth = {TOKEN_HEADER: srv.token}
    alive = lambda: get(p, "/api/info", headers=auth) == 200
    bad = {
        "path traversal": b"GET /../../../../etc/passwd HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" % p,
        "encoded traversal": b"GET /%%2e%%2e/%%2e%%2e/etc/passwd HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" % p,
        "traversal after a route": b"GET /api/../../etc/passwd HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" % p,
        "a source file's name": b"GET /app.js/../index.html HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" % p,
        "the spectral file itself": b"GET /two.exr HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" % p,
        "a 100 kB URL": b"GET /" + b"a" * 100000 + b" HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" % p,
        "a long query": b"GET /api/weights?" + b"x" * 20000 + b" HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" % p,
        "a garbage request line": b"GARBAGE\r\n\r\n",
        "no HTTP version": b"GET /\r\n\r\n",
        "a bad version": b"GET / HTTP/9.9\r\nHost: 127.0.0.1:%d\r\n\r\n" % p,
        "a header without colon": b"GET / HTTP/1.1\r\nHost 127.0.0.1\r\n\r\n",
        "a 100 kB header": b"GET / HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nX: " % p + b"y" * 100000 + b"\r\n\r\n",
        "binary bytes": bytes(range(256)) * 4 + b"\r\n\r\n",
        "a foreign Host (DNS rebinding)": request_bytes(p, "GET", "/api/info", auth, host="evil.example:%d" % p),
        "an unknown method": b"BREW / HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" % p,
        "a huge body": b"POST /api/save HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n%s: %s\r\nContent-Length: 99999999\r\n\r\n" % (
            p, TOKEN_HEADER.encode(), srv.token.encode()),
    }
    for what, data in bad.items():
        # The server answers an over-long request before reading all of it and closes; the unread
        # bytes can turn its close into a reset that swallows the answer. Three tries.
        for _ in range(3):
            status = raw(p, data, timeout=25)
            if status:
                break
        check(400 <= status < 500 and alive(), "%s: %d, server up" % (what, status))
    api = {
        "save outside the folder": ("POST", "/api/save?file=../escape.png"),
        "save to an absolute path": ("POST", "/api/save?file=%2Ftmp%2Fescape.png"),
        "save a hidden file": ("POST", "/api/save?file=.hidden.png"),
        "save an unknown format": ("POST", "/api/save?file=x.bmp"),
        "save by GET": ("GET", "/api/save?file=x.png"),
        "a csv: spectrum": ("GET", "/api/weights?light.side=csv:%2Fetc%2Fpasswd"),
        "an unknown light": ("GET", "/api/weights?light.fill=D65"),
        "an unknown key": ("GET", "/api/weights?colour=red"),
        "a bad exposure": ("GET", "/api/weights?exposure=1e9"),
        "an unknown display": ("GET", "/api/weights?display=Nope"),
        "an unknown display shader": ("GET", "/api/display?name=..%2F..%2Fetc"),
        "a transport layer out of range": ("GET", "/api/transport?light=9&group=0"),
        "a negative group": ("GET", "/api/transport?light=0&group=-1"),
        "a probe outside the image": ("GET", "/api/probe?x=64&y=0"),
    }
    for what, (method, path) in api.items():
        status, body = http(srv.base.rstrip("/") + path, method, srv.token)
        check(400 <= status < 500 and alive(), "%s: %d %s" % (what, status, body[:120].decode(errors="replace")))
    status, body = http(srv.base + "api/weights?light.side=A&light.back=off&exposure=1", token=srv.token)
    w = json.loads(body)
    check(status == 200 and abs(sum(w["lights"][0]["w"][16:32]) - 2.0) < 1e-9 and not w["lights"][1]["on"],
          "weights: white under A at exposure 1 has Y = 2, back off")


def check_access(srv, save_dir):
    """Each /api route: 403 without the secret, with a wrong one, from another page; else answered."""
    p = srv.port
    own = "http://127.0.0.1:%d" % p
    wrong = secrets.token_hex(16)
    while wrong == srv.token:
        wrong = secrets.token_hex(16)
    refused = {
        "no secret": {},
        "a wrong secret": {TOKEN_HEADER: wrong},
        "the secret's first half": {TOKEN_HEADER: srv.token[:16]},
        "the secret from another site (Origin)": {TOKEN_HEADER: srv.token, "Origin": "http://localhost:8000"},
        "the secret from a null origin": {TOKEN_HEADER: srv.token, "Origin": "null"},
        "the secret, Sec-Fetch-Site: cross-site": {TOKEN_HEADER: srv.token, "Sec-Fetch-Site": "cross-site"},
        "the secret, Sec-Fetch-Site: same-site": {TOKEN_HEADER: srv.token, "Sec-Fetch-Site": "same-site"},
    }
    page = {TOKEN_HEADER: srv.token, "Origin": own, "Sec-Fetch-Site": "same-origin"}
    for method, path in API_ROUTES:
        for what, headers in refused.items():
            status = get(p, path, headers=headers, method=method)
            check(status == 403, "%s %s with %s: %d" % (method, path, what, status))
        check(not os.path.exists(os.path.join(save_dir, "forged.png")), "%s %s: nothing saved yet" % (method, path))
        status = get(p, path, headers=page, method=method)
        check(status == 200, "%s %s as the page sends it: %d" % (method, path, status))
    check(get(p, "/") == 200 and all(get(p, "/" + js) == 200 for js in ("state.js", "plots.js", "gpu.js", "app.js")),
          "the page and its scripts need no secret (they hold no data)")
    check(len(srv.refused()) >= len(API_ROUTES) * len(refused), "-v reports each refused request (%d lines)" %
          len(srv.refused()))
    os.remove(os.path.join(save_dir, "forged.png"))


def check_save_limits(srv, save_dir, served):
    """Save refuses the served file, a hard link to it and a symbolic link (here to a file outside)."""
    outside_dir = tempfile.mkdtemp(prefix="plt-out-")
    outside = os.path.join(outside_dir, "outside.png")
    with open(outside, "wb") as f:
        f.write(b"outside")
    hard = os.path.join(save_dir, "hard_link.exr")
    link = os.path.join(save_dir, "sym_link.png")
    os.link(served, hard)
    os.symlink(outside, link)
    try:
        before = snapshot(save_dir)
        for name, why in [(os.path.basename(served), "the served file"), ("hard_link.exr", "a hard link to it"),
                          ("sym_link.png", "a symbolic link to a file outside the folder")]:
            status, body = http(srv.base + "api/save?file=" + name, "POST", srv.token)
            check(status == 400, "Save to %s: %d %s" % (why, status, body[:160].decode(errors="replace")))
        check(snapshot(save_dir) == before, "the save folder is byte for byte as it was")
        with open(outside, "rb") as f:
            check(f.read() == b"outside", "the file outside the save folder is unchanged")
    finally:
        os.remove(hard)
        os.remove(link)
        shutil.rmtree(outside_dir)


def check_one_server_per_port(relight, exr, save_dir, srv):
    """A second server on the port of a running one is refused (exit 2); the first keeps serving."""
    proc = subprocess.Popen([relight, exr, "--serve", "--port", str(srv.port), "--save-dir", save_dir],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        out, err = proc.communicate(timeout=30)
        rc = proc.returncode
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
        rc = None
    want = "prizma-relight: error: --bind 127.0.0.1 --port %d: cannot listen there (address not local, or port in use)" % srv.port
    check(rc == 2 and err.strip() == want and out == "", "a second server on port %d: exit %s, %r" % (srv.port, rc, err.strip()))
    check(get(srv.port, "/api/info", headers={TOKEN_HEADER: srv.token}) == 200, "the first server still answers")


def check_slow_connections(relight, exr, save_dir, sig):
    """32 idle and 32 slowloris connections (a header trickled a byte at a time, never finished):
    the page still answers, and `sig` ends the server within 1 s with them open."""
    srv = Server(relight, exr, save_dir)
    p = srv.port
    idle = [socket.create_connection(("127.0.0.1", p), timeout=30) for _ in range(32)]
    slow = [socket.create_connection(("127.0.0.1", p), timeout=30) for _ in range(32)]
    header = b"GET /api/info HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n" % p + b"X-Slow: " + b"s" * 4000
    done = threading.Event()

    def trickle():
        i = 0
        while not done.is_set() and i < len(header):
            for s in slow:
                try:
                    s.send(header[i:i + 1])
                except OSError:
                    pass
            i += 1
            done.wait(0.02)

    t = threading.Thread(target=trickle)
    t.start()
    try:
        answered = 0
        for _ in range(10):
            answered += get(p, "/api/info", headers={TOKEN_HEADER: srv.token}) == 200
        check(answered == 10, "with 64 idle and slow connections open the page answers (%d of 10)" % answered)
        rc = srv.stop(sig)
        check(rc == 0 and srv.stop_seconds < 1.0, "%s with 64 connections open ends the server in %.2f s (exit %s)" % (
            signal.Signals(sig).name, srv.stop_seconds, rc))
    finally:
        done.set()
        t.join()
        for s in idle + slow:
            s.close()
        if srv.proc.poll() is None:
            srv.stop(signal.SIGKILL)


def test_server(relight, workdir):
    save_dir = tempfile.mkdtemp(prefix="plt-save-")
    served = os.path.join(save_dir, "two.exr")
    shutil.copyfile(os.path.join(workdir, "two.exr"), served)
    try:
        srv = Server(relight, served, save_dir)
        check(get(srv.port, "/") == 200 and get(srv.port, "/api/info", headers={TOKEN_HEADER: srv.token}) == 200,
              "the page and /api/info answer 200")
        check_bad_requests(srv)
        check(not os.path.exists(os.path.join(os.path.dirname(save_dir), "escape.png")) and
              not os.path.exists("/tmp/escape.png"), "nothing written outside --save-dir")
        check_access(srv, save_dir)
        check_save_limits(srv, save_dir, served)
        check_one_server_per_port(relight, served, save_dir, srv)
        rc = srv.stop(signal.SIGINT)
        check(rc == 0, "SIGINT stops the server (exit %s)" % rc)
        for sig in (signal.SIGTERM, signal.SIGINT):
            check_slow_connections(relight, served, save_dir, sig)
        # A non-loopback bind warns on stderr (0.0.0.0 listens on loopback too).
        proc = subprocess.Popen([relight, served, "--serve", "--bind", "0.0.0.0"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        url = proc.stdout.readline().strip()
        proc.send_signal(signal.SIGTERM)
        err = proc.communicate(timeout=10)[1]
        check(url.startswith("http://0.0.0.0:") and "#token=" in url and "warning" in err and "not a loopback" in err,
              "--bind 0.0.0.0 warns: %r" % err.strip())
    finally:
        shutil.rmtree(save_dir)
    return 0
