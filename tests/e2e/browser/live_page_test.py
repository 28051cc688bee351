#!/usr/bin/python3
"""End-to-end tests of prizma-relight --serve (tests/e2e/browser.cmake).

  live_page_test.py server  RELIGHT WORKDIR   the HTTP server through plain sockets (server_checks.py):
                                              bad requests, the access rules of every /api route,
                                              Save's limits, one server per port, 64 idle and slow
                                              connections, SIGINT and SIGTERM within 1 s
  live_page_test.py browser RELIGHT WORKDIR   headless Chromium (SwiftShader WebGL2) draws the page
                                              for several states; its canvas must match
                                              `prizma-relight ... -o ref.png` within 2/255 per
                                              channel on >= 99.9 % of the pixels, and "Save" must
                                              write the very same image; pages of other origins
                                              cannot use the server (cross_site.py)

WORKDIR holds two.exr, one.exr and wide.exr (make_fixture); the browser test makes two_coef.exr and
two_compact.exr from two.exr with `prizma-relight compress` (k = 5 of 16 bins), which the page relights
from their coefficients and must match `prizma-relight` (without --exact) on. It also checks that the
display is shown in its canvas colour space (Display P3: drawingBufferColorSpace 'display-p3';
Rec.2020, which no canvas holds: Display P3 instead, said on the page, and the canvas then compared
with the CLI's Display P3 image while Save writes Rec.2020), that every spectrum kind of a light shows
its parameters at once and keeps them in the URL, and that the image, the controls and the probe's
spectrum are all inside the window at 1400×900 and 1920×1080. With --mri FILE (a render of data/scenes/mri.json,
lights key and env) the browser test also draws that real-data file in several states. With --fluor
FILE (a small render of data/scenes/fluorescent_dye.json, lights key and sky: bispectral channels)
it draws that file too (the re-radiation included, observers switched so that K is fetched again)
and checks the probe's excitation-emission map against the file's T.<in>nm.<out>nm channels.
Exit 77 (ctest SKIP_RETURN_CODE) when chromium, chromedriver or selenium are missing, 1 then with
CI=true; 1 on any failure. Every wait is for a condition the page sets (data-state, data-frame,
data-error, data-pixel), never a fixed time; scratch folders are short temporary ones (a clone's
path may be long).
"""
import base64
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import urllib.parse

from live_server import Server, check, failures, http, missing_tool

TOLERANCE = 2          # per channel, in 1/255
MIN_FRACTION = 0.999   # of the pixels within the tolerance
WAIT_SECONDS = 180     # the longest any condition may take (a loaded machine, software WebGL)


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


def wait_for(browser, script, ok, *args):
    """Runs `script` in the page until ok(its result): a condition the page sets, for at most
    WAIT_SECONDS. Returns the last result."""
    from selenium.common.exceptions import TimeoutException
    from selenium.webdriver.support.ui import WebDriverWait
    last = [None]

    def done(driver):
        last[0] = driver.execute_script(script, *args)
        return ok(last[0])

    try:
        WebDriverWait(browser, WAIT_SECONDS, poll_frequency=0.05).until(done)
    except TimeoutException:
        pass
    return last[0]


def check_excitation_emission_map(browser, srv, exr):
    """The probe's map on the page: the pixel's M[out][in] of the chosen light, as the file holds them,
    the largest cell drawn in the ramp's top colour."""
    import numpy as np
    info = json.loads(http(srv.base + "api/info", token=srv.token)[1])
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
        got = wait_for(browser, "const c = document.getElementById('eem'); return [c.dataset.pixel, c.dataset.light,"
                                " c.dataset.values, c.dataset.cell];", lambda g: g[0] == "%d,%d" % (x, y) and g[1] == light)
        if not got or got[0] != "%d,%d" % (x, y) or got[1] != light:
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


def test_browser(relight, workdir, mri=None, fluor=None, denoised=None):
    chromium = shutil.which("chromium")
    driver_path = shutil.which("chromedriver") or ("/usr/bin/chromedriver" if os.path.exists("/usr/bin/chromedriver") else None)
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        webdriver = None
    if not chromium or not driver_path or webdriver is None:
        return missing_tool("chromium, chromium-driver or python3-selenium")
    make_coefficient_files(relight, workdir)
    # The profile in a short temporary folder, not under the build folder: a clone's path may be long.
    with tempfile.TemporaryDirectory(prefix="plt-") as profile:
        opts = webdriver.ChromeOptions()
        opts.binary_location = chromium
        for flag in ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--enable-unsafe-swiftshader",
                     "--use-angle=swiftshader", "--disable-background-networking", "--disable-extensions",
                     "--disable-sync", "--no-first-run", "--disable-default-apps", "--mute-audio",
                     "--user-data-dir=" + profile]:
            opts.add_argument(flag)
        browser = webdriver.Chrome(service=Service(driver_path), options=opts)
        try:
            check_pages(browser, relight, workdir, mri, fluor)
            if denoised:
                check_denoised_title(browser, relight, workdir, denoised)
            from cross_site import check_cross_site
            check_cross_site(browser, relight, workdir)
        finally:
            browser.quit()
    return 0


def make_coefficient_files(relight, workdir):
    """two_coef.exr (coefficients beside the bins) and two_compact.exr (coefficients only) from two.exr,
    at a bound loose enough (ΔE00 5) that k = 5 of 16 and the compressed relight differs visibly from
    the exact one: a page drawing the bins would fail the comparison."""
    for name, extra in (("two_coef.exr", []), ("two_compact.exr", ["--compact"])):
        run = subprocess.run([relight, "compress", os.path.join(workdir, "two.exr"), "-o", os.path.join(workdir, name),
                              "--max-error", "5", "-q", *extra], capture_output=True, text=True)
        if run.returncode != 0:
            raise RuntimeError("prizma-relight compress: " + run.stderr.strip())


DRAWN = "const c = document.getElementById('relit'); return [c.dataset.state, c.dataset.error || null, " \
        "Number(c.dataset.frame), location.hash];"

# What the last frame shows: the display drawn, the canvas's colour space, the page's notice about it,
# what it relit from, and the frame time it reports.
SHOWN = """const c = document.getElementById('relit');
const text = (id) => document.getElementById(id) ? document.getElementById(id).textContent : null;
return [c.dataset.shownDisplay || null, c.getContext('webgl2').drawingBufferColorSpace || null, text('notice'),
        c.dataset.transport || null, c.dataset.frameMs || null, text('frameinfo'), text('transport')];"""
CANVAS_SPACE = {"sRGB": "srgb", "Display P3": "display-p3"}


def open_page(browser, srv, state, joiner):
    """Opens the URL the server printed with `state` appended after `joiner` ('&', or '#' as before
    there was a secret); the page must draw that state and leave no secret in the address bar."""
    browser.get(srv.url + joiner + state)
    drawn, err, frames, hash_ = wait_for(browser, DRAWN, lambda r: r[0] == state or r[1])
    check(drawn == state and hash_ == "#" + state and srv.token not in (drawn or "") + hash_,
          "the printed URL + %r + state: drawn %r (error %r), address bar %r, no secret in either" % (
              joiner, drawn, err, hash_))
    stored = browser.execute_script("return sessionStorage.getItem('prizma-relight-token');")
    check(stored == srv.token, "the secret is kept in the tab's sessionStorage")


def check_pages(browser, relight, workdir, mri, fluor):
    import numpy as np
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
        ("two_coef.exr", "light.side=A&light.back=LED-B1*1.5&exposure=0.5&cmf=1931&display=sRGB&adapt=0",
         "coefficients (k = 5 of 16): A and a blue LED"),
        ("two_coef.exr", "light.side=F11&light.back=off&exposure=1&cmf=1964&display=Display%20P3&adapt=1",
         "coefficients: F11 alone, 1964 observer, P3, adapted"),
        ("two_compact.exr", "light.side=D65&light.back=A*2&exposure=0&cmf=1931&display=Rec.2020&adapt=0",
         "a compact file (coefficients only), Rec.2020"),
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
    page_saved = set()  # files whose Save was clicked on the page
    try:
        for name, state, what in cases:
            if name not in servers:
                servers[name] = Server(relight, os.path.join(workdir, name), workdir)
                open_page(browser, servers[name], state, "&" if len(servers) % 2 else "#")
            srv = servers[name]
            browser.execute_script("location.hash = arguments[0];", state)
            drawn, err, _, _ = wait_for(browser, DRAWN, lambda r: r[0] == state or r[1])
            if drawn != state:
                check(False, "%s: the page drew %r (error %r)" % (what, drawn, err))
                continue
            shown = check_shown(browser, name, state, what)
            w, h, data = browser.execute_script(READ_CANVAS)
            canvas = np.frombuffer(base64.b64decode(data), dtype=np.uint8).reshape(h, w, 4)[::-1, :, :3]
            ref = cli_image(relight, workdir, name, state, "ref_%d.png" % len(refs), what)
            if ref is None:
                continue
            refs[state] = ref
            # The canvas against the CLI's image of the display it shows (the state's, or the one shown
            # instead); Save against the state's.
            drawn_ref = ref if shown == display_of(state) else cli_image(
                relight, workdir, name, state, "ref_shown_%d.png" % len(refs), what, shown)
            if drawn_ref is None:
                continue
            diff = np.abs(canvas.astype(int) - drawn_ref.astype(int))
            within = float(np.mean(np.all(diff <= TOLERANCE, axis=2)))
            check(canvas.shape == drawn_ref.shape and within >= MIN_FRACTION,
                  "%s: %.4f %% of pixels within %d/255 of prizma-relight's %s image (max diff %d, mean %.3f, ref mean %.1f)" % (
                      what, 100 * within, TOLERANCE, shown, diff.max(), diff.mean(), drawn_ref.mean()))
            if name == "two_coef.exr" and name not in page_saved:
                check_discriminates(relight, workdir, state, ref, what)
            # Save writes the exact CPU image: the page's own button for the first state of each file.
            if name not in page_saved:
                page_saved.add(name)
                saved = save_from_page(browser, workdir, "page_saved.png")
            else:
                status, body = http(srv.base + "api/save?file=saved.png&" + state, "POST", srv.token)
                saved = read_png(os.path.join(workdir, "saved.png")) if status == 200 else None
            check(saved is not None and np.array_equal(saved, ref), "%s: Save writes prizma-relight's image" % what)
        if fluor and fluor in servers:
            check_excitation_emission_map(browser, servers[fluor], fluor)
        frames = browser.execute_script("return Number(document.getElementById('relit').dataset.frame);")
        check(frames >= 2, "data-frame counts the frames drawn (%d)" % frames)
        # A reload of the state-only address still works in this tab (the secret is in sessionStorage).
        browser.refresh()
        drawn, err, frames, _ = wait_for(browser, DRAWN, lambda r: r[2] >= 1 or r[1])
        check(frames >= 1 and not err, "a reload of %r draws again (error %r)" % (browser.current_url, err))
        # The comparisons can fail: the states differ from each other.
        states = list(refs)
        check(len(states) >= 5 and not np.array_equal(refs[states[0]], refs[states[4]]) and refs[states[1]].max() == 0,
              "the references differ between states, all-off is black")
        check_spectrum_menu(browser, servers["two.exr"])
        servers["wide.exr"] = Server(relight, os.path.join(workdir, "wide.exr"), workdir)
        for name in ["wide.exr"] + ([mri] if mri else []):
            check_layout(browser, servers[name], name)
    finally:
        for srv in servers.values():
            check(srv.stop() == 0, "server for %s stopped cleanly" % srv.url)


MENU_STATE = "light.side=D65&light.back=off&exposure=0&cmf=1931&display=sRGB&adapt=0"


def check_spectrum_menu(browser, srv):
    """Issue 25 item 1: choosing blackbody, gaussian or "other spec…" in a light's spectrum menu shows
    that kind's parameter rows at once (and only those), and the spec, with what the rows then set,
    goes into the URL and is drawn."""
    from selenium.webdriver.support.ui import Select
    open_page(browser, srv, MENU_STATE, "&")
    fs = browser.find_element("css selector", "fieldset[data-light=side]")
    rows = {f: fs.find_element("css selector", "[data-field=%s]" % f) for f in ("temp", "centre", "fwhm", "custom")}

    def drawn_with(spec, what):
        want = "light.side=" + spec
        got = wait_for(browser, DRAWN, lambda r: r[0] and want + "&" in r[0] or r[1])
        check(got[0] and want + "&" in got[0] and got[3].startswith("#" + want + "&"),
              "%s: the URL and the drawn state hold %s (%r, error %r)" % (what, want, got[3], got[1]))

    def set_row(field, value):
        box = rows[field].find_element("css selector", "input[type=number], input[type=text]")
        browser.execute_script("arguments[0].value = arguments[1]; arguments[0].dispatchEvent(new Event('change'));",
                               box, value)

    for kind, label, spec, visible, then in [
        ("blackbody", "blackbody", "blackbody:3200K", {"temp"}, ("temp", "5600", "blackbody:5600K")),
        ("gaussian", "gaussian", "gaussian:550:40", {"centre", "fwhm"}, ("fwhm", "25", "gaussian:550:25")),
        ("custom", "other spec…", "gaussian:550:25", {"custom"}, ("custom", "box:500:560", "box:500:560")),
    ]:
        Select(fs.find_element("css selector", "select.kind")).select_by_visible_text(label)
        shown = {f for f, row in rows.items() if row.is_displayed()}
        check(shown == visible, "choosing %s shows its rows %s at once (shown: %s)" % (label, sorted(visible), sorted(shown)))
        drawn_with(spec, "choosing " + label)
        set_row(then[0], then[1])
        drawn_with(then[2], "%s, its %s set to %s" % (label, then[0], then[1]))
    # The URL's spec brings the menu and the rows back (a reload of the state-only address).
    browser.refresh()
    wait_for(browser, DRAWN, lambda r: r[2] >= 1 or r[1])
    fs = browser.find_element("css selector", "fieldset[data-light=side]")
    kind = Select(fs.find_element("css selector", "select.kind")).first_selected_option.text
    text = fs.find_element("css selector", "[data-field=custom] input").get_attribute("value")
    check(kind == "other spec…" and text == "box:500:560",
          "a reload of the URL shows the spec in its row again (menu %r, spec %r)" % (kind, text))


LAYOUT = """const r = (el) => { if (!el) return [-1, -1, -1, -1];  // missing: counted as outside
  const b = el.getBoundingClientRect(); return [b.left, b.top, b.right, b.bottom]; };
const q = (s) => Array.from(document.querySelectorAll(s));
const c = document.getElementById('relit'), box = document.getElementById('stagebox');
return {view: [window.innerWidth, window.innerHeight], dpr: window.devicePixelRatio,
        parts: Object.fromEntries([['image', c], ['pixel spectrum plot', document.getElementById('probeplot')],
                                   ['pixel read-out', document.getElementById('probe')],
                                   ['A/B ΔE read-out', document.getElementById('compare')],
                                   ['light spectra plot', document.getElementById('spectra')],
                                   ['frame time', document.getElementById('frameinfo')]]
                                  .concat(q('#panel fieldset').map((f, i) => ['controls ' + i, f]))
                                  .map(([k, el]) => [k, r(el)])),
        zoom: Number(c.dataset.zoom), size: [c.width, c.height], box: box ? [box.clientWidth, box.clientHeight] : [1, 1],
        rendering: getComputedStyle(c).imageRendering};"""


TITLES = "return [document.getElementById('title').textContent, document.title];"


def check_denoised_title(browser, relight, workdir, denoised):
    """Issue 23: a denoised file says so in the page's title line and the tab's title; a raw file
    does not (the check can fail)."""
    for exr, is_denoised in ((denoised, True), (os.path.join(workdir, "two.exr"), False)):
        srv = Server(relight, exr, workdir)
        try:
            browser.get(srv.url)
            wait_for(browser, DRAWN, lambda r: r[2] >= 1 or r[1])
            line, tab = wait_for(browser, TITLES, lambda t: "(prizma " in t[0])
            says = "denoised by prizma" in line and "non-local means on luminance" in line and tab.endswith("(denoised)")
            quiet = "denoised" not in line and "denoised" not in tab
            check(says if is_denoised else quiet, "%s: the title line %r and the tab's %r %s" % (
                os.path.basename(exr), line, tab, "say it is denoised" if is_denoised else "say nothing of denoising"))
        finally:
            check(srv.stop() == 0, "server for %s stopped cleanly" % srv.url)


def check_layout(browser, srv, name):
    """Issue 25 item 2: in a browser window of 1400×900 (a laptop screen; headless Chromium leaves a
    1400×757 page inside it, as a browser with its tab and address bars does) and of 1920×1080, the
    image, every control, the probe's spectrum plot, the A/B read-out and the frame time are inside the
    page together; the image is as large as fits at a whole zoom (crisp, pixelated) for these small
    files."""
    browser.get(srv.url)  # the file's starting state
    wait_for(browser, DRAWN, lambda r: r[2] >= 1 or r[1])
    for width, height in ((1400, 900), (1920, 1080)):
        browser.set_window_size(width, height)
        # The page's viewport follows the window a moment later (headless Chromium resizes it
        # asynchronously): wait for both.
        wait_for(browser, "return [window.outerWidth, window.outerHeight, window.innerWidth];",
                 lambda g: g == [width, height, width])
        lay = wait_for(browser, "return (" + "() => {" + LAYOUT + "})();",
                       lambda l: (l["zoom"] or 0) >= 1 and (l["zoom"] + 1) * max(l["size"][0] / max(l["box"][0], 1),
                                                                           l["size"][1] / max(l["box"][1], 1)) > l["dpr"])
        vw, vh = lay["view"]
        outside = [k for k, (l, t, r, b) in lay["parts"].items() if l < 0 or t < 0 or r > vw + 0.5 or b > vh + 0.5]
        check(vw == width and vh >= 0.8 * height and not outside,
              "%s in a %d×%d window (page %d×%d): image, controls, probe plot and read-outs all inside (outside: %s %r)" % (
                  name, width, height, vw, vh, outside or "none", lay["parts"] if outside else ""))
        w, h = lay["size"]
        zoom, (bw, bh) = lay["zoom"] or 0, lay["box"]
        fits = zoom * w <= bw * lay["dpr"] + 0.5 and zoom * h <= bh * lay["dpr"] + 0.5
        larger_fits = (zoom + 1) * w <= bw * lay["dpr"] and (zoom + 1) * h <= bh * lay["dpr"]
        check(zoom == int(zoom) and zoom >= 2 and fits and not larger_fits and lay["rendering"] == "pixelated",
              "%s at %d×%d: %d×%d image drawn at the largest whole zoom that fits its %d×%d box (%s×, %s)" % (
                  name, width, height, w, h, bw, bh, zoom, lay["rendering"]))
    browser.set_window_size(1400, 900)


def display_of(state):
    return dict(urllib.parse.parse_qsl(state))["display"]


def cli_image(relight, workdir, name, state, out, what, display=None):
    """prizma-relight FILE (the state's options; `display` instead of the state's when given) -o out:
    the image read back, or None after a failed check."""
    args = cli_args(state)
    if display is not None:
        args[args.index("--display") + 1] = display
    path = os.path.join(workdir, out)
    run = subprocess.run([relight, os.path.join(workdir, name), *args, "-o", path], capture_output=True, text=True)
    if run.returncode != 0:
        check(False, "%s: prizma-relight failed: %s" % (what, run.stderr.strip()))
        return None
    return read_png(path)


def check_shown(browser, name, state, what):
    """What the page says it drew: the state's display in its canvas colour space, or for Rec.2020 (no
    canvas colour space holds it) Display P3 with a notice naming both; the transport it relit from;
    its frame time. Returns the display shown."""
    shown, space, notice, transport, frame_ms, frame_text, transport_text = browser.execute_script(SHOWN)
    display = display_of(state)
    if display == "Rec.2020":
        check(shown == "Display P3" and space == "display-p3" and "Rec.2020" in notice and
              "BT.2020 primaries" in notice and "Shown instead: Display P3" in notice and "Save writes Rec.2020" in notice,
              "%s: no canvas holds Rec.2020: Display P3 shown (canvas %r) and said: %r" % (what, space, notice))
    else:
        check(shown == display and space == CANVAS_SPACE[display] and not notice,
              "%s: %s drawn with drawingBufferColorSpace %r (got %r, %r), no notice (%r)" % (
                  what, display, CANVAS_SPACE[display], shown, space, notice))
    coefficients = name in ("two_coef.exr", "two_compact.exr")
    check(transport == ("coefficients" if coefficients else "bins") and
          (not coefficients or ("k = 5" in (transport_text or "") and "ΔE00 p99" in transport_text)),
          "%s: relit from the %s, and the page says so (%r)" % (what, transport, transport_text))
    check(frame_ms is not None and float(frame_ms) > 0 and frame_text is not None and re.match(r"frame [0-9.]+ ms \(relight", frame_text or ""),
          "%s: the page shows its frame time (%r)" % (what, frame_text))
    return shown


def check_discriminates(relight, workdir, state, ref, what):
    """The compressed relight differs from the exact one (--exact) by more than the tolerance on more
    pixels than the comparison allows: a page drawing the bins would have failed it."""
    import numpy as np
    run = subprocess.run([relight, os.path.join(workdir, "two_coef.exr"), "--exact", *cli_args(state), "-o",
                          os.path.join(workdir, "ref_exact.png")], capture_output=True, text=True)
    exact = read_png(os.path.join(workdir, "ref_exact.png")) if run.returncode == 0 else None
    off = float(np.mean(np.any(np.abs(exact.astype(int) - ref.astype(int)) > TOLERANCE, axis=2))) if exact is not None else 0
    check(off > 1 - MIN_FRACTION, "%s: the bins' image differs from the coefficients' on %.1f %% of the pixels "
          "(so the comparison tells them apart)" % (what, 100 * off))


def save_from_page(browser, workdir, name):
    """Clicks the page's Save with `name`; the saved image once the page reports it, else None."""
    browser.execute_script("document.getElementById('saved').textContent = '';"
                           "document.getElementById('savename').value = arguments[0];"
                           "document.getElementById('save').click();", name)
    said = wait_for(browser, "return document.getElementById('saved').textContent;", lambda t: bool(t))
    ok = check(said.startswith("saved ") and said.endswith(name), "the page's Save: %r" % said)
    return read_png(os.path.join(workdir, name)) if ok else None


def main():
    args = sys.argv[1:]
    mri = fluor = denoised = None
    if "--mri" in args:
        i = args.index("--mri")
        mri = os.path.abspath(args[i + 1])
        del args[i:i + 2]
    if "--fluor" in args:
        i = args.index("--fluor")
        fluor = os.path.abspath(args[i + 1])
        del args[i:i + 2]
    if "--denoised" in args:
        i = args.index("--denoised")
        denoised = os.path.abspath(args[i + 1])
        del args[i:i + 2]
    if len(args) != 3 or args[0] not in ("server", "browser"):
        print(__doc__)
        return 2
    mode, relight, workdir = args[0], os.path.abspath(args[1]), os.path.abspath(args[2])
    if mode == "server":
        from server_checks import test_server
        rc = test_server(relight, workdir)
    else:
        rc = test_browser(relight, workdir, mri, fluor, denoised)
    if failures:
        print("%d check(s) failed" % len(failures))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
