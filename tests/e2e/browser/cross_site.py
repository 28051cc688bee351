"""live_page_test.py browser: pages of other origins try to use the live page's server in Chromium.

An attacker page is served by a plain Python HTTP server on another loopback port and opened as
http://localhost:Q/ (another site: Sec-Fetch-Site cross-site) and http://127.0.0.1:Q/ (the same site,
another origin). It tries a no-cors POST of /api/save (a new file, the served file, an existing
image), GETs of /api/transport and /api/info without the secret and with a guessed one, and a form
POST. The server must refuse every one (its -v lines name each), and the served file and the save
folder must be byte for byte as before.
"""
import http.server
import os
import shutil
import tempfile
import threading

from selenium.common.exceptions import TimeoutException
from selenium.webdriver.support.ui import WebDriverWait

from live_server import Server, check, snapshot

ATTACK = """<!DOCTYPE html><html><body>
<form id="f" method="POST" action="%(target)s/api/save?file=form.png" target="sink"></form>
<iframe name="sink"></iframe>
<script>
const target = '%(target)s';
window.results = {};
async function attempt(name, f) {
  try { const r = await f(); window.results[name] = 'resolved ' + r.type + ' ' + r.status; }
  catch (e) { window.results[name] = 'rejected ' + e.name; }
}
(async () => {
  const guess = {'X-Prizma-Token': '0123456789abcdef0123456789abcdef'};
  await attempt('save a new file', () => fetch(target + '/api/save?file=x.exr', {method: 'POST', mode: 'no-cors'}));
  await attempt('save over the served file', () => fetch(target + '/api/save?file=two.exr', {method: 'POST', mode: 'no-cors'}));
  await attempt('save over an image', () => fetch(target + '/api/save?file=keep.png', {method: 'POST', mode: 'no-cors'}));
  await attempt('read transport', () => fetch(target + '/api/transport?light=0&group=0'));
  await attempt('read transport no-cors', () => fetch(target + '/api/transport?light=0&group=0', {mode: 'no-cors'}));
  await attempt('read transport, guessed secret', () => fetch(target + '/api/transport?light=0&group=0', {headers: guess}));
  await attempt('read info, guessed secret', () => fetch(target + '/api/info', {headers: guess}));
  document.getElementById('f').submit();
  window.done = true;
})();
</script></body></html>"""

# What reaches the server from one attacker page: five requests, two preflights (OPTIONS) for the
# guessed secret (their GETs are never sent), one form POST.
REQUESTS_PER_PAGE = 8


def serve_attacker(target):
    """A plain HTTP server on a free loopback port whose every page is ATTACK aimed at `target`."""
    body = (ATTACK % {"target": target}).encode()

    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self):
            self.send_response(200)
            self.send_header("Content-Type", "text/html")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args):
            pass

    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    return httpd


def check_cross_site(browser, relight, workdir):
    folder = tempfile.mkdtemp(prefix="plt-xs-")
    served = os.path.join(folder, "two.exr")
    shutil.copyfile(os.path.join(workdir, "two.exr"), served)
    with open(os.path.join(folder, "keep.png"), "wb") as f:
        f.write(b"an image the attacker would replace")
    before = snapshot(folder)
    srv = Server(relight, served, folder)
    attacker = serve_attacker(srv.base.rstrip("/"))
    try:
        port = attacker.server_address[1]
        for origin, site in [("http://localhost:%d" % port, "another site"), ("http://127.0.0.1:%d" % port, "the same site")]:
            seen = len(srv.refused())
            browser.get(origin + "/attack.html")
            # The page's fetches end before window.done; the form POST (a navigation of the frame)
            # after it: the condition is the server's count of refused requests.
            try:
                WebDriverWait(browser, 180, poll_frequency=0.05).until(
                    lambda d: d.execute_script("return window.done === true") and
                    len(srv.refused()) - seen >= REQUESTS_PER_PAGE)
            except TimeoutException:
                pass
            lines = srv.refused()[seen:]
            results = browser.execute_script("return window.results")
            ok = len(lines) == REQUESTS_PER_PAGE and all(": a request from another page" in l for l in lines)
            check(ok, "a page of %s (%s): the server refused its %d requests as from another page%s" % (
                site, origin, REQUESTS_PER_PAGE, "" if ok else ": %s; in the page: %r" % (lines, results)))
            check(not results["read transport"].startswith("resolved") and
                  not results["read transport, guessed secret"].startswith("resolved"),
                  "%s: the page reads nothing (fetch: %s)" % (site, results["read transport"]))
        check(snapshot(folder) == before, "the served file and the save folder are byte for byte unchanged")
    finally:
        attacker.shutdown()
        rc = srv.stop()
        check(rc == 0, "the attacked server stopped cleanly (exit %s)" % rc)
        shutil.rmtree(folder)
