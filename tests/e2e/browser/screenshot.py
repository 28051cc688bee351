#!/usr/bin/python3
"""Screenshot of the live page (docs/relight.md): serves FILE, opens the page in headless Chromium
(SwiftShader WebGL2) at the state FRAGMENT, picks two pixels (A at 45 %/50 %, B at 66 %/38 % of the
image), hovers a third, and saves the window as OUT.png.

    screenshot.py PRIZMA_RELIGHT FILE FRAGMENT OUT.png [--serve options…]
"""
import subprocess
import sys
import tempfile
import time

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains


def main():
    if len(sys.argv) < 5:
        print(__doc__)
        return 2
    relight, exr, state, out = sys.argv[1:5]
    proc = subprocess.Popen([relight, exr, "--serve", *sys.argv[5:]], stdout=subprocess.PIPE, text=True)
    url = proc.stdout.readline().strip()
    with tempfile.TemporaryDirectory(prefix="live-page-shot-") as profile:
        opts = webdriver.ChromeOptions()
        for flag in ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--enable-unsafe-swiftshader",
                     "--use-angle=swiftshader", "--disable-background-networking", "--window-size=1100,1040",
                     "--hide-scrollbars", "--user-data-dir=" + profile]:
            opts.add_argument(flag)
        browser = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)
        try:
            browser.get(url + ("&" + state if state else ""))  # url: …/#token=SECRET
            for _ in range(600):
                frame = browser.execute_script("return document.getElementById('relit').dataset.frame")
                if frame and int(frame) >= 1:
                    break
                time.sleep(0.1)
            canvas = browser.find_element("id", "relit")
            w, h = canvas.size["width"], canvas.size["height"]
            at = lambda fx, fy: (int(w * fx) - w // 2, int(h * fy) - h // 2)  # offsets from the centre
            ActionChains(browser).move_to_element_with_offset(canvas, *at(0.45, 0.5)).click().perform()
            time.sleep(0.5)
            ActionChains(browser).move_to_element_with_offset(canvas, *at(0.66, 0.38)).click().perform()
            time.sleep(1.0)
            ActionChains(browser).move_to_element_with_offset(canvas, *at(0.52, 0.56)).perform()
            time.sleep(1.5)
            browser.save_screenshot(out)
            print(browser.execute_script("return document.getElementById('probe').textContent + '\\n' + "
                                         "document.getElementById('compare').textContent"))
        finally:
            browser.quit()
            proc.terminate()
            proc.wait()
    return 0


if __name__ == "__main__":
    sys.exit(main())
