#!/usr/bin/python3
"""Screenshot of the live page (docs/relight.md): serves FILE, opens the page in headless Chromium
(SwiftShader WebGL2) in a browser window of W×H (default 1400×900, a laptop screen; headless Chromium
leaves a page of 1400×757 inside it, as a browser's tab and address bars do) at the state FRAGMENT,
picks two pixels (A at 45 %/50 %, B at 66 %/38 % of the image), hovers a third, and saves the page
as OUT.png. Every wait is for what the page shows (the frame, the ΔE read-out, the probe), not a time.

    screenshot.py PRIZMA_RELIGHT FILE FRAGMENT OUT.png [--size WxH] [--serve options…]
"""
import subprocess
import sys
import tempfile

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.support.ui import WebDriverWait

WAIT_SECONDS = 300  # software WebGL on a loaded machine


def main():
    args = sys.argv[1:]
    size = (1400, 900)
    if "--size" in args:
        i = args.index("--size")
        size = tuple(int(v) for v in args[i + 1].split("x"))
        del args[i:i + 2]
    if len(args) < 4:
        print(__doc__)
        return 2
    relight, exr, state, out = args[:4]
    proc = subprocess.Popen([relight, exr, "--serve", *args[4:]], stdout=subprocess.PIPE, text=True)
    url = proc.stdout.readline().strip()
    with tempfile.TemporaryDirectory(prefix="live-page-shot-") as profile:
        opts = webdriver.ChromeOptions()
        for flag in ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--enable-unsafe-swiftshader",
                     "--use-angle=swiftshader", "--disable-background-networking", "--hide-scrollbars",
                     "--window-size=%d,%d" % size, "--user-data-dir=" + profile]:
            opts.add_argument(flag)
        browser = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)
        text = lambda id_: browser.execute_script("return document.getElementById(arguments[0]).textContent;", id_)
        wait = WebDriverWait(browser, WAIT_SECONDS, poll_frequency=0.1)
        try:
            browser.get(url + ("&" + state if state else ""))  # url: …/#token=SECRET
            wait.until(lambda b: b.execute_script("return Number(document.getElementById('relit').dataset.frame) >= 1"))
            canvas = browser.find_element("id", "relit")
            w, h = canvas.size["width"], canvas.size["height"]
            at = lambda fx, fy: (int(w * fx) - w // 2, int(h * fy) - h // 2)  # offsets from the centre
            ActionChains(browser).move_to_element_with_offset(canvas, *at(0.45, 0.5)).click().perform()
            wait.until(lambda b: "click a second pixel" in text("compare"))
            ActionChains(browser).move_to_element_with_offset(canvas, *at(0.66, 0.38)).click().perform()
            wait.until(lambda b: "ΔE00" in text("compare"))
            ActionChains(browser).move_to_element_with_offset(canvas, *at(0.52, 0.56)).perform()
            wait.until(lambda b: text("probe").startswith("pixel (") and
                       b.execute_script("return !!document.getElementById('probeplot').dataset.yMax"))
            browser.save_screenshot(out)
            print(text("probe") + "\n" + text("compare") + "\n" + text("frameinfo"))
        finally:
            browser.quit()
            proc.terminate()
            proc.wait()
    return 0


if __name__ == "__main__":
    sys.exit(main())
