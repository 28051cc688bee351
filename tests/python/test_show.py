"""An image shows itself: Image._repr_png_ / Image.png are prizma-relight's PNG (Jupyter's rich
display, through IPython's own formatter), and prizma.serve runs the tool's live page for an image in
memory, from a private temporary file removed when it stops (docs/python.md, "Showing an image")."""
import json
import os
import shutil
import stat
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

import numpy as np
import pytest

import prizma
from conftest import cli_error, run_tool, tool

oiio = pytest.importorskip("OpenImageIO")

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
TOKEN_HEADER = "X-Prizma-Token"


def decode(png_bytes, tmp_path, name):
    """The PNG's size and 8-bit pixels, decoded by OpenImageIO (a file: its Python binding has no
    memory reader in Debian 12's 2.4)."""
    path = tmp_path / name
    path.write_bytes(png_bytes)
    inp = oiio.ImageInput.open(str(path))
    assert inp, oiio.geterror()
    try:
        spec = inp.spec()
        return (spec.width, spec.height, spec.nchannels), inp.read_image(0, 0, 0, spec.nchannels, "uint8")
    finally:
        inp.close()


def private_folders(folder, prefix):
    return sorted(n for n in os.listdir(folder) if n.startswith(prefix))


def test_repr_png_is_the_tools_png(tiny_exr, tmp_path, monkeypatch):
    monkeypatch.setenv("TMPDIR", str(tmp_path))  # where the PNG's private folder is made (and removed)
    cli = tmp_path / "cli.png"
    run_tool("relight", tiny_exr, "-o", cli)
    data = prizma.read(tiny_exr)._repr_png_()
    assert isinstance(data, bytes) and data.startswith(PNG_SIGNATURE)
    shape, ours = decode(data, tmp_path, "ours.png")
    assert shape == (8, 8, 3)
    _, theirs = decode(cli.read_bytes(), tmp_path, "theirs.png")
    assert ours.max() > 10  # not a black square
    np.testing.assert_array_equal(ours, theirs)
    assert private_folders(tmp_path, "prizma-png-") == []


def test_png_takes_relights_settings(tiny_exr, tmp_path):
    cli = tmp_path / "cli.png"
    run_tool("relight", tiny_exr, "--light", "side=A", "--light", "sky=off", "--exposure", "1", "--display",
             "Display P3", "-o", cli)
    data = prizma.read(tiny_exr).png({"side": "A", "sky": None}, exposure=1, display="Display P3")
    _, ours = decode(data, tmp_path, "ours.png")
    _, theirs = decode(cli.read_bytes(), tmp_path, "theirs.png")
    np.testing.assert_array_equal(ours, theirs)
    default = decode(prizma.read(tiny_exr).png(), tmp_path, "default.png")[1]
    assert not np.array_equal(ours, default)


def test_png_errors_are_relights(tiny_exr, tmp_path, monkeypatch):
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    image = prizma.read(tiny_exr)
    for lights, display in (({"side": "D66"}, "sRGB"), ({"lamp": "A"}, "sRGB"), (None, "Display Q3")):
        with pytest.raises(prizma.InputError) as want:
            prizma.relight(image, lights, display=display)
        with pytest.raises(prizma.InputError) as got:
            image.png(lights, display=display)
        assert str(got.value) == str(want.value)
    assert private_folders(tmp_path, "prizma-png-") == []


def test_ipython_displays_the_png(tiny_exr):
    formatters = pytest.importorskip("IPython.core.formatters")  # Debian's python3-ipython
    image = prizma.read(tiny_exr)
    data, _ = formatters.DisplayFormatter().format(image)
    assert data["image/png"] == image._repr_png_()
    assert data["text/plain"] == repr(image)


# ---------------------------------------------------------------------------------------------
# prizma.serve


def http(url, token=None):
    req = urllib.request.Request(url, headers={TOKEN_HEADER: token} if token else {})
    try:
        with urllib.request.urlopen(req, timeout=60) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def test_serve_an_image_in_memory(tiny_exr, tmp_path, capsys):
    assert os.path.samefile(prizma._prizma.relight_tool_path(), tool("relight"))
    image = prizma.read(tiny_exr)
    with prizma.serve(image, port=0, save_dir=tmp_path) as server:
        assert capsys.readouterr().out == server.url + "\n"  # printed as prizma-relight --serve prints it
        base, _, token = server.url.partition("/#token=")
        assert base == f"http://127.0.0.1:{server.port}" and len(token) == 32
        folder = server._folder
        exr = os.path.join(folder, "image.exr")
        assert stat.S_IMODE(os.stat(folder).st_mode) == 0o700
        assert stat.S_IMODE(os.stat(exr).st_mode) == 0o600
        assert prizma.checksum(prizma.read(exr)) == prizma.checksum(image)
        status, page = http(base + "/")
        assert status == 200 and b"<html" in page.lower()
        assert http(base + "/api/info")[0] == 403  # not without the secret
        status, body = http(base + "/api/info", token)
        assert status == 200
        info = json.loads(body)
        assert (info["source"], info["width"], info["height"]) == ("image.exr", 8, 8)
        assert [l["name"] for l in info["lights"]] == ["side", "sky"]
        assert server.running
    assert not server.running and server._proc.returncode == 0
    assert not os.path.exists(folder)
    with pytest.raises(urllib.error.URLError):
        urllib.request.urlopen(base + "/", timeout=10)
    assert server.stop() == 0  # a second stop does nothing


def api(method, url, headers):
    """The status and JSON body of a request to the page's API with these headers."""
    req = urllib.request.Request(url, data=b"" if method == "POST" else None, method=method, headers=headers)
    try:
        with urllib.request.urlopen(req, timeout=60) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read())


def test_serve_keeps_the_servers_safety_rules(tiny_exr, tmp_path):
    """prizma.serve is prizma-relight --serve (issue 21): every API call needs the run's secret and
    the page's own origin, and Save never replaces the served file (a file served from save_dir)."""
    served = tmp_path / "served.exr"
    shutil.copyfile(tiny_exr, served)
    before = served.read_bytes()
    keep = tmp_path / "keep.png"
    keep.write_bytes(b"not to be replaced by another page")
    with prizma.serve(served, save_dir=tmp_path) as server:
        base, _, token = server.url.partition("/#token=")
        own = {TOKEN_HEADER: token, "Origin": base, "Sec-Fetch-Site": "same-origin"}
        for why, headers in {
            "no secret": {"Origin": base},
            "a wrong secret": {TOKEN_HEADER: "0" * 32, "Origin": base},
            "another origin": {TOKEN_HEADER: token, "Origin": "http://localhost:8000"},
            "another site": {TOKEN_HEADER: token, "Sec-Fetch-Site": "cross-site"},
        }.items():
            for name in ("new.png", "keep.png", "served.exr"):
                status, body = api("POST", f"{base}/api/save?file={name}", headers)
                assert status == 403, (why, name, status, body)
            assert api("GET", base + "/api/info", headers)[0] == 403, why
        assert api("GET", base + "/api/info", own)[0] == 200
        status, body = api("POST", f"{base}/api/save?file=served.exr", own)
        assert status == 400 and "is the file being served; Save never replaces it" in body["error"], body
        status, body = api("POST", f"{base}/api/save?file=saved.png", own)
        assert status == 200 and body["file"] == "saved.png", body
    assert served.read_bytes() == before
    assert keep.read_bytes() == b"not to be replaced by another page"
    assert (tmp_path / "saved.png").read_bytes().startswith(PNG_SIGNATURE)
    assert not (tmp_path / "new.png").exists()


def test_serve_starts_where_the_cli_starts(tiny_exr, tmp_path, capsys):
    server = prizma.serve(tiny_exr, save_dir=tmp_path, lights={"side": "A", "sky": None}, exposure=1)
    try:
        base, _, token = server.url.partition("/#token=")
        state = json.loads(http(base + "/api/info", token)[1])["state"]
        assert state.startswith("light.side=A&light.sky=off&exposure=1&"), state
    finally:
        server.stop()
    assert server._folder is None  # a file is served as it is: no copy


def test_serve_errors_are_the_tools(tiny_exr, tmp_path, monkeypatch):
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    missing = tmp_path / "missing.exr"
    want, code = cli_error("relight", missing, "--serve")
    with pytest.raises(prizma.InputError) as e:
        prizma.serve(missing)
    assert code == 2 and str(e.value) == want
    with pytest.raises(prizma.InputError, match=r'^--light side: '):
        prizma.serve(prizma.read(tiny_exr), lights={"side": "D66"})
    for lights in ((np.array([400.0, 700.0]), np.array([1.0, 1.0])), {"side": (np.array([400.0]), np.array([1.0]))}):
        with pytest.raises(prizma.InputError, match=r'^lights(\["side"\])?: prizma.serve takes '):
            prizma.serve(tiny_exr, lights=lights)
    for port in (-1, 65536, "80", 1.5):
        with pytest.raises(prizma.InputError, match=r"^port: must be an integer within 0 … 65535"):
            prizma.serve(tiny_exr, port=port)
    assert private_folders(tmp_path, "prizma-serve-") == []  # the refused image's file is gone too
    with prizma.serve(tiny_exr, save_dir=tmp_path) as first:
        with pytest.raises(prizma.InputError, match="--port"):
            prizma.serve(tiny_exr, port=first.port, save_dir=tmp_path)


def test_serve_shows_the_tools_warnings(tiny_exr, tmp_path, capsys):
    """What the tool says on stderr before it serves (a bind that is not loopback) reaches the user."""
    with prizma.serve(tiny_exr, bind="0.0.0.0", save_dir=tmp_path) as server:
        assert server.url.startswith(f"http://0.0.0.0:{server.port}/#token=")
        err = capsys.readouterr().err
    assert "prizma-relight: warning: --bind 0.0.0.0 is not a loopback address" in err, err


def test_serve_stops_when_python_exits(tiny_exr, tmp_path):
    """A server left running is stopped, and its file removed, when the interpreter exits."""
    code = ("import prizma, sys; s = prizma.serve(prizma.read(sys.argv[1])); "
            "print(s._proc.pid, s._folder, flush=True)")
    proc = subprocess.run([sys.executable, "-c", code, str(tiny_exr)], capture_output=True, text=True, timeout=60,
                          cwd=tmp_path, env=dict(os.environ, TMPDIR=str(tmp_path)))
    assert proc.returncode == 0, proc.stderr
    pid, folder = proc.stdout.splitlines()[-1].split()
    assert not os.path.exists(folder)
    deadline = time.monotonic() + 10
    while os.path.exists(f"/proc/{pid}") and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not os.path.exists(f"/proc/{pid}")


def test_serve_page_draws_in_chromium(tiny_exr, tmp_path):
    """The page prizma.serve opens draws the image in memory in headless Chromium (SwiftShader WebGL2),
    as tests/e2e/browser's live-page tests open the tool's; its screenshot is left in the test's folder."""
    webdriver = pytest.importorskip("selenium.webdriver")
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.support.ui import WebDriverWait
    if not os.access("/usr/bin/chromedriver", os.X_OK):
        pytest.skip("chromium-driver is not installed (scripts/setup installs it)")
    opts = webdriver.ChromeOptions()
    for flag in ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--enable-unsafe-swiftshader",
                 "--use-angle=swiftshader", "--disable-background-networking", "--window-size=1400,900",
                 "--user-data-dir=" + str(tmp_path / "profile")]:
        opts.add_argument(flag)
    with prizma.serve(prizma.read(tiny_exr), save_dir=tmp_path) as server:
        browser = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)
        try:
            browser.get(server.url)
            WebDriverWait(browser, 240, poll_frequency=0.1).until(
                lambda b: b.execute_script("return Number(document.getElementById('relit').dataset.frame) >= 1"))
            canvas = browser.execute_script("const c = document.getElementById('relit'); return [c.width, c.height];")
            assert canvas[0] > 0 and canvas[1] > 0
            assert "image.exr" in browser.find_element("tag name", "body").text
            browser.save_screenshot(str(tmp_path / "served.png"))
        finally:
            browser.quit()
