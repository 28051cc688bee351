#!/usr/bin/python3
"""End-to-end tests of prizma-relight --serve (tests/e2e/browser.cmake).

  live_page_test.py server  RELIGHT WORKDIR   the HTTP server: bad requests (path traversal, long
                                              URLs, malformed requests, foreign Host, save outside
                                              the folder, csv: specs) each get a 4xx and the server
                                              stays up; SIGINT and SIGTERM stop it with exit 0
  live_page_test.py browser RELIGHT WORKDIR   headless Chromium (SwiftShader WebGL2) draws the page
                                              for several states; its canvas must match
                                              `prizma-relight ... -o ref.png` within 2/255 per
                                              channel on >= 99.9 % of the pixels, and "Save" must
                                              write the very same image

WORKDIR holds two.exr and one.exr (make_fixture). With --mri FILE (a render of data/scenes/mri.json,
lights key and env) the browser test also draws that real-data file in several states. With --fluor
FILE (a small render of data/scenes/fluorescent_dye.json, lights key and sky: bispectral channels)
it draws that file too (the re-radiation included, observers switched so that K is fetched again)
and checks the probe's excitation-emission map against the file's T.<in>nm.<out>nm channels. Exit 77 (ctest SKIP_RETURN_CODE) when chromium,
chromedriver or selenium are missing; 1 on any failure.
"""
import base64
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.parse
import urllib.request

SKIP = 77
TOLERANCE = 2          # per channel, in 1/255
MIN_FRACTION = 0.999   # of the pixels within the tolerance
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what, flush=True)
    if not ok:
        failures.append(what)


class Server:
    """prizma-relight FILE --serve on a free loopback port; the URL is its first line of stdout."""

    def __init__(self, relight, exr, workdir, extra=()):
        self.proc = subprocess.Popen([relight, exr, "--serve", "--save-dir", workdir, *extra],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        line = self.proc.stdout.readline().strip()
        if not line.startswith("http://127.0.0.1:"):
            self.proc.kill()
            raise RuntimeError("no URL from prizma-relight --serve: %r %s" % (line, self.proc.stderr.read()))
        self.url = line
        self.port = int(line.rsplit(":", 1)[1].strip("/"))

    def stop(self, sig=signal.SIGTERM):
        self.proc.send_signal(sig)
        try:
            return self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
            return None


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


def get(port, path, host=None):
    host = host or "127.0.0.1:%d" % port
    return raw(port, ("GET %s HTTP/1.1\r\nHost: %s\r\nConnection: close\r\n\r\n" % (path, host)).encode())


def http(url, method="GET"):
    req = urllib.request.Request(url, data=b"" if method == "POST" else None, method=method)
    try:
        with urllib.request.urlopen(req, timeout=30) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def test_server(relight, workdir):
    srv = Server(relight, os.path.join(workdir, "two.exr"), workdir)
    p = srv.port
    alive = lambda: get(p, "/api/info") == 200
    check(get(p, "/") == 200 and alive(), "the page and /api/info answer 200")
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
        "a foreign Host (DNS rebinding)": b"GET /api/info HTTP/1.1\r\nHost: evil.example:%d\r\n\r\n" % p,
        "an unknown method": b"BREW / HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" % p,
        "a huge body": b"POST /api/save HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nContent-Length: 99999999\r\n\r\n" % p,
    }
    for what, data in bad.items():
        # The server answers an over-long request before reading all of it and closes; the unread
        # bytes can turn its close into a reset that swallows the answer. Three tries.
        for _ in range(3):
            # httplib answers a declared body above the payload limit with 413 only once its 10 s read
            # timeout has passed (the other handler threads keep serving meanwhile): wait past it.
            status = raw(p, data, timeout=25 if what == "a huge body" else 10)
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
        status, body = http(srv.url.rstrip("/") + path, method)
        check(400 <= status < 500 and alive(), "%s: %d %s" % (what, status, body[:120].decode(errors="replace")))
    check(not os.path.exists(os.path.join(os.path.dirname(workdir), "escape.png")) and
          not os.path.exists("/tmp/escape.png"), "nothing written outside --save-dir")
    status, body = http(srv.url + "api/weights?light.side=A&light.back=off&exposure=1")
    w = json.loads(body)
    check(status == 200 and abs(sum(w["lights"][0]["w"][16:32]) - 2.0) < 1e-9 and not w["lights"][1]["on"],
          "weights: white under A at exposure 1 has Y = 2, back off")
    rc = srv.stop(signal.SIGINT)
    check(rc == 0, "SIGINT stops the server (exit %s)" % rc)
    srv = Server(relight, os.path.join(workdir, "two.exr"), workdir)
    rc = srv.stop(signal.SIGTERM)
    check(rc == 0, "SIGTERM stops the server (exit %s)" % rc)
    # A non-loopback bind warns on stderr (0.0.0.0 listens on loopback too).
    proc = subprocess.Popen([relight, os.path.join(workdir, "two.exr"), "--serve", "--bind", "0.0.0.0"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    url = proc.stdout.readline().strip()
    proc.send_signal(signal.SIGTERM)
    err = proc.communicate(timeout=10)[1]
    check(url.startswith("http://0.0.0.0:") and "warning" in err and "not a loopback" in err,
          "--bind 0.0.0.0 warns: %r" % err.strip())


def cli_args(state):
    """The prizma-relight options of a page state (the fragment)."""
    args = []
    for part in state.split("&"):
        key, value = [urllib.parse.unquote(x) for x in part.split("=", 1)]
        if key.startswith("light."):
            args += ["--light", key[6:] + "=" + value]
        elif key == "exposure":
            args += ["--exposure", value]
        elif key == "cmf":
            args += ["--cmf", value]
        elif key == "display":
            args += ["--display", value]
        elif key == "adapt" and value == "1":
            args += ["--adapt"]
    return args


def read_png(path):
    import OpenImageIO as oiio
    import numpy as np
    # ImageInput, not ImageBuf: an ImageBuf goes through OpenImageIO's shared ImageCache, which keys
    # on the file name and modification time, so saved.png rewritten within the same second would
    # read back as the previous image.
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise RuntimeError("cannot read %s: %s" % (path, oiio.geterror()))
    spec = inp.spec()
    pixels = inp.read_image(oiio.UINT8)
    inp.close()
    return np.asarray(pixels).reshape(spec.height, spec.width, -1)[:, :, :3]


READ_CANVAS = """
const c = document.getElementById('relit');
const gl = c.getContext('webgl2');
const px = new Uint8Array(c.width * c.height * 4);
gl.readPixels(0, 0, c.width, c.height, gl.RGBA, gl.UNSIGNED_BYTE, px);
let s = '';
for (let i = 0; i < px.length; i += 8192) s += String.fromCharCode.apply(null, px.subarray(i, i + 8192));
return [c.width, c.height, btoa(s)];
"""


def read_exr_channels(path):
    """Every channel of an EXR by name, as (height, width) float arrays."""
    import OpenImageIO as oiio
    import numpy as np
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise RuntimeError("cannot read %s: %s" % (path, oiio.geterror()))
    spec = inp.spec()
    pixels = np.asarray(inp.read_image(oiio.FLOAT)).reshape(spec.height, spec.width, spec.nchannels)
    inp.close()
    return {name: pixels[:, :, k] for k, name in enumerate(spec.channelnames)}


def channel_nm(nm):
    return ("%.6f" % nm).replace(".", ",") + "nm"


def check_excitation_emission_map(browser, srv, exr):
    """The probe's map on the page: the pixel's M[out][in] of the chosen light, as the file holds them,
    the largest cell drawn in the ramp's top colour."""
    import numpy as np
    info = json.loads(http(srv.url + "api/info")[1])
    edges = info["bins"]
    centre = lambda b: 0.5 * (edges[b] + edges[b + 1])
    channels = read_exr_channels(exr)
    for light in [l["name"] for l in info["lights"]]:
        # The pixel where this light's re-radiation is largest: at a few samples per pixel a given
        # pixel may have seen none for a dim light (all pairs 0), and the check below is of the drawing.
        pairs = [n for n in channels if n.startswith(light + ".T.") and n.count(".") == 3 and n.endswith("nm")]
        rerad = sum(channels[n] for n in pairs)
        y, x = (int(v) for v in np.unravel_index(np.argmax(rerad), rerad.shape))
        browser.execute_script("document.getElementById('eemlight').value = arguments[0]; probe(arguments[1], arguments[2]);",
                               light, x, y)
        deadline = time.time() + 30
        got = None
        while time.time() < deadline:
            got = browser.execute_script("const c = document.getElementById('eem'); return [c.dataset.pixel, c.dataset.light,"
                                         " c.dataset.values, c.dataset.cell];")
            if got[0] == "%d,%d" % (x, y) and got[1] == light:
                break
            time.sleep(0.05)
        if not got or got[1] != light:
            check(False, "excitation-emission map of light %s at (%d, %d) not drawn: %r" % (light, x, y, got))
            continue
        values = json.loads(got[2])
        worst = 0.0
        for i, o, v in values:
            want = float(channels["%s.T.%s.%s" % (light, channel_nm(centre(i)), channel_nm(centre(o)))][y, x])
            worst = max(worst, abs(v - want) / max(abs(want), 1e-30) if want else abs(v))
        check(len(values) == len(info["reradiation"]["pairs"]) and worst < 1e-6,
              "map of light %s at (%d, %d): %d pairs as the file holds them (worst relative difference %.2g)" % (
                  light, x, y, len(values), worst))
        # The largest value's cell is drawn in the ramp's top colour (252, 255, 164).
        i, o, v = max(values, key=lambda t: t[2])
        cell = int(got[3])
        rgb = browser.execute_script(
            "const c = document.getElementById('eem'); return Array.from(c.getContext('2d').getImageData("
            "arguments[0], arguments[1], 1, 1).data);", int((i + 0.5) * cell), int(120 - (o + 0.5) * cell))
        check(v > 0 and all(abs(a - b) <= 1 for a, b in zip(rgb[:3], [252, 255, 164])),
              "map of light %s: the largest pair (%d → %d, %.4g) drawn in the top colour (%r)" % (light, i, o, v, rgb))


def test_browser(relight, workdir, mri=None, fluor=None):
    chromium = shutil.which("chromium")
    driver_path = shutil.which("chromedriver") or ("/usr/bin/chromedriver" if os.path.exists("/usr/bin/chromedriver") else None)
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        webdriver = None
    if not chromium or not driver_path or webdriver is None:
        print("skip: needs chromium, chromium-driver and python3-selenium")
        return SKIP
    import numpy as np

    opts = webdriver.ChromeOptions()
    opts.binary_location = chromium
    for flag in ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--enable-unsafe-swiftshader",
                 "--use-angle=swiftshader", "--disable-background-networking", "--disable-extensions",
                 "--disable-sync", "--no-first-run", "--disable-default-apps", "--mute-audio",
                 "--user-data-dir=" + os.path.join(workdir, "chromium-profile")]:
        opts.add_argument(flag)
    browser = webdriver.Chrome(service=Service(driver_path), options=opts)
    cases = [
        ("two.exr", "light.side=D65&light.back=A&exposure=0&cmf=1931&display=sRGB&adapt=0", "the file's default lights"),
        ("two.exr", "light.side=off&light.back=off&exposure=0&cmf=1931&display=sRGB&adapt=0", "all lights off"),
        ("two.exr", "light.side=D65&light.back=A*2&exposure=6&cmf=1931&display=sRGB&adapt=0", "exposure +6 (clipped)"),
        ("two.exr", "light.side=D65&light.back=off&exposure=-7.5&cmf=1931&display=sRGB&adapt=0", "exposure -7.5"),
        ("two.exr", "light.side=F11&light.back=off&exposure=0&cmf=1931&display=sRGB&adapt=0", "a spiky light (F11)"),
        ("two.exr", "light.side=A&light.back=LED-B1*1.5&exposure=0.5&cmf=1931&display=Display%20P3&adapt=0",
         "Display P3"),
        ("two.exr", "light.side=blackbody:2700K&light.back=gaussian:600:30*0.7&exposure=0&cmf=1964&display=Rec.2020&adapt=1",
         "blackbody + gaussian, 1964 observer, Rec.2020, adapted"),
        ("two.exr", "light.side=LED-V1&light.back=D50&exposure=-0.3&cmf=2012-10&display=sRGB&adapt=0", "CIE 2012 10°"),
        ("one.exr", "light.key=D65&exposure=0&cmf=1931&display=sRGB&adapt=0", "a 1-bin file"),
        ("one.exr", "light.key=gaussian:550:40&exposure=1&cmf=2012-2&display=Display%20P3&adapt=1", "a 1-bin file, P3"),
    ]
    if mri:
        cases += [
            (mri, "light.key=D65&light.env=D65*0.3&exposure=0&cmf=1931&display=sRGB&adapt=0", "the MRI render, its own lights"),
            (mri, "light.key=blackbody:3200K&light.env=off&exposure=1&cmf=1931&display=Display%20P3&adapt=1",
             "the MRI render, warm key light only, P3, adapted"),
            (mri, "light.key=F11&light.env=LED-B3*0.5&exposure=-0.5&cmf=2012-2&display=sRGB&adapt=0",
             "the MRI render, F11 and a blue LED"),
        ]
    if fluor:
        cases += [
            (fluor, "light.key=LED-V1&light.sky=off&exposure=0&cmf=1931&display=sRGB&adapt=0",
             "the fluorescent render under a violet LED (re-radiation)"),
            (fluor, "light.key=LED-V1&light.sky=D65*0.2&exposure=0.5&cmf=1964&display=Display%20P3&adapt=1",
             "the fluorescent render, 1964 observer (K fetched again), P3, adapted"),
            (fluor, "light.key=D65&light.sky=D65*0.2&exposure=0&cmf=2012-2&display=sRGB&adapt=0",
             "the fluorescent render under its own lights, CIE 2012 2°"),
        ]
    servers = {}
    refs = {}
    try:
        for name, state, what in cases:
            if name not in servers:
                servers[name] = Server(relight, os.path.join(workdir, name), workdir)
                browser.get(servers[name].url)
                time.sleep(0.2)
            srv = servers[name]
            browser.execute_script("location.hash = arguments[0];", state)
            deadline = time.time() + 60
            drawn = err = None
            while time.time() < deadline:
                drawn, err = browser.execute_script(
                    "const c = document.getElementById('relit'); return [c.dataset.state, c.dataset.error || null];")
                if drawn == state or err:
                    break
                time.sleep(0.05)
            if drawn != state:
                check(False, "%s: the page drew %r (error %r)" % (what, drawn, err))
                continue
            w, h, data = browser.execute_script(READ_CANVAS)
            canvas = np.frombuffer(base64.b64decode(data), dtype=np.uint8).reshape(h, w, 4)[::-1, :, :3]
            ref_path = os.path.join(workdir, "ref_%d.png" % len(refs))
            run = subprocess.run([relight, os.path.join(workdir, name), *cli_args(state), "-o", ref_path],
                                 capture_output=True, text=True)
            if run.returncode != 0:
                check(False, "%s: prizma-relight failed: %s" % (what, run.stderr.strip()))
                continue
            ref = read_png(ref_path)
            refs[state] = ref
            diff = np.abs(canvas.astype(int) - ref.astype(int))
            within = float(np.mean(np.all(diff <= TOLERANCE, axis=2)))
            check(canvas.shape == ref.shape and within >= MIN_FRACTION,
                  "%s: %.4f %% of pixels within %d/255 (max diff %d, mean %.3f, ref mean %.1f)" % (
                      what, 100 * within, TOLERANCE, diff.max(), diff.mean(), ref.mean()))
            # Save writes the exact CPU image.
            status, body = http(srv.url + "api/save?file=saved.png&" + state, "POST")
            saved = read_png(os.path.join(workdir, "saved.png")) if status == 200 else None
            check(saved is not None and np.array_equal(saved, ref), "%s: Save writes prizma-relight's image" % what)
        if fluor and fluor in servers:
            check_excitation_emission_map(browser, servers[fluor], fluor)
        frames = browser.execute_script("return Number(document.getElementById('relit').dataset.frame);")
        check(frames >= 2, "data-frame counts the frames drawn (%d)" % frames)
        # The comparisons can fail: the states differ from each other.
        states = list(refs)
        check(len(states) >= 5 and not np.array_equal(refs[states[0]], refs[states[4]]) and refs[states[1]].max() == 0,
              "the references differ between states, all-off is black")
    finally:
        browser.quit()
        for srv in servers.values():
            check(srv.stop() == 0, "server for %s stopped cleanly" % srv.url)
    return 0


def main():
    args = sys.argv[1:]
    mri = fluor = None
    if "--mri" in args:
        i = args.index("--mri")
        mri = os.path.abspath(args[i + 1])
        del args[i:i + 2]
    if "--fluor" in args:
        i = args.index("--fluor")
        fluor = os.path.abspath(args[i + 1])
        del args[i:i + 2]
    if len(args) != 3 or args[0] not in ("server", "browser"):
        print(__doc__)
        return 2
    mode, relight, workdir = args[0], os.path.abspath(args[1]), os.path.abspath(args[2])
    rc = test_server(relight, workdir) if mode == "server" else test_browser(relight, workdir, mri, fluor)
    if rc == SKIP:
        return SKIP
    if failures:
        print("%d check(s) failed" % len(failures))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
