#!/usr/bin/python3
"""Opens the built documentation site in headless Chromium and checks what a reader sees.

    scripts/docs-browser-test.py SITE_DIR SCREENSHOT_DIR

The site is served on 127.0.0.1 (Sphinx's search loads its index by script, which browsers refuse
over file://), and Chromium is driven over the DevTools protocol. Checked:

- the home page, the tutorial, the C++ page of the allocators and the Python API page load with
  their title and expected text, and every image on them has loaded (naturalWidth > 0);
- the tutorial shows its executed outputs: the optimum it printed and its three plots;
- the C++ page documents DpRerunAllocator with the header's comment, and the Python page
  ontime.solve with its signature;
- the search page, asked for DpRerunAllocator, lists the allocators' C++ page among its results.

Each page is screenshotted into SCREENSHOT_DIR (kept by CI as artifacts). Exits 1 on the first
failed check, naming it.
"""

from __future__ import annotations

import base64
import contextlib
import functools
import http.server
import json
import pathlib
import shutil
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request

import websocket

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextlib.contextmanager
def serve(folder: pathlib.Path):
    handler = functools.partial(QuietHandler, directory=str(folder))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()


class QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


class Browser:
    """One headless Chromium and one page of it, driven over the DevTools protocol."""

    def __init__(self):
        self.profile = tempfile.mkdtemp(prefix="ontime-docs-chromium-")
        port = free_port()
        # Flags for a root user in a container with no network, GPU or display.
        self.process = subprocess.Popen(
            [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
             "--disable-background-networking", "--disable-component-update", "--disable-sync",
             "--disable-dev-shm-usage", "--hide-scrollbars", f"--user-data-dir={self.profile}",
             f"--remote-debugging-port={port}", "--window-size=1280,900", "about:blank"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + 30
        targets = None
        while time.monotonic() < deadline:
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=2) as r:
                    targets = [t for t in json.load(r) if t.get("type") == "page"]
                if targets:
                    break
            except OSError:
                pass
            time.sleep(0.2)
        if not targets:
            self.close()
            raise RuntimeError("Chromium did not open its DevTools port within 30 s")
        self.socket = websocket.create_connection(targets[0]["webSocketDebuggerUrl"], timeout=60)
        self.next_id = 0
        self.call("Page.enable")
        self.call("Runtime.enable")

    def call(self, method: str, **params):
        self.next_id += 1
        self.socket.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            message = json.loads(self.socket.recv())
            if message.get("id") == self.next_id:
                if "error" in message:
                    raise RuntimeError(f"{method}: {message['error']}")
                return message.get("result", {})

    def evaluate(self, expression: str):
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in result:
            raise RuntimeError(f"script failed: {expression}: {result['exceptionDetails']}")
        return result["result"].get("value")

    def open(self, url: str, ready: str = "true", timeout: float = 30):
        """Loads `url` and waits until the page is complete and `ready` (a JS expression) holds."""
        self.call("Page.navigate", url=url)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.evaluate(f"document.readyState === 'complete' && location.href === {json.dumps(url)} "
                             f"&& Boolean({ready})"):
                return
            time.sleep(0.2)
        raise AssertionError(f"{url}: not ready within {timeout} s ({ready})")

    def screenshot(self, path: pathlib.Path, full_page: bool = False, top: float | None = None):
        """The viewport, the whole page (up to 6000 px), or 900 px of the page from `top`."""
        params = {"format": "png"}
        if top is not None:
            params.update(captureBeyondViewport=True, clip={"x": 0, "y": top, "width": 1280, "height": 900, "scale": 1})
        elif full_page:
            size = self.call("Page.getLayoutMetrics")["cssContentSize"]
            params.update(captureBeyondViewport=True,
                          clip={"x": 0, "y": 0, "width": 1280, "height": min(size["height"], 6000), "scale": 1})
        data = self.call("Page.captureScreenshot", **params)["data"]
        path.write_bytes(base64.b64decode(data))

    def close(self):
        with contextlib.suppress(Exception):
            self.socket.close()
        self.process.terminate()
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
        shutil.rmtree(self.profile, ignore_errors=True)


def check(condition: bool, what: str):
    if not condition:
        raise AssertionError(what)
    print(f"docs-browser-test: ok: {what}")


def images_loaded(browser: Browser, page: str, at_least: int):
    images = browser.evaluate(
        "Array.from(document.images).map(i => ({src: i.getAttribute('src'), w: i.naturalWidth}))")
    broken = [i["src"] for i in images if i["w"] == 0]
    check(len(images) >= at_least and not broken,
          f"{page}: {len(images)} images, all loaded (at least {at_least}; broken: {broken})")


def text_of(browser: Browser) -> str:
    return browser.evaluate("document.body.innerText")


def main() -> int:
    site = pathlib.Path(sys.argv[1]).resolve()
    shots = pathlib.Path(sys.argv[2]).resolve()
    shots.mkdir(parents=True, exist_ok=True)
    for old in shots.glob("*.png"):
        old.unlink()
    with serve(site) as base:
        browser = Browser()
        try:
            # The home page: the title, the two commands, the navigation to the guides.
            browser.open(f"{base}/index.html")
            text = text_of(browser)
            check(browser.evaluate("document.title").startswith("OnTime"), "home page: title")
            check("./scripts/reproduce-table1.sh" in text and "Getting started" in text,
                  "home page: the commands and the guides' navigation")
            check(browser.evaluate("document.querySelectorAll('button.copybtn').length") >= 1,
                  "home page: code blocks have copy buttons")
            browser.screenshot(shots / "home.png")

            # The tutorial: executed outputs and its three plots.
            browser.open(f"{base}/tutorial.html")
            text = text_of(browser)
            check("optimum 0." in text and "refine move(" in text, "tutorial: the solve cell's printed output")
            check("of the optimum" in text and ("Status.success" in text or "Status.failure" in text),
                  "tutorial: the comparison and the session's outputs")
            images_loaded(browser, "tutorial", 3)
            plots = browser.evaluate("Array.from(document.querySelectorAll('div.nboutput img'))"
                                     ".filter(i => i.naturalWidth > 300).length")
            check(plots == 3, f"tutorial: its three plots are shown ({plots} in the cells' outputs)")
            browser.screenshot(shots / "tutorial.png", full_page=True)

            # The C++ reference of the allocators: DpRerunAllocator with its header's comment.
            browser.open(f"{base}/api/cpp/allocators.html")
            text = text_of(browser)
            check("DpRerunAllocator" in text and "DP_Rerun, Algorithm 1" in text,
                  "C++ allocators page: DpRerunAllocator and dp_rerun.hpp's description")
            check("Before every step, evaluates PS(k, l_k, CT, ET_k)" in text,
                  "C++ allocators page: the header comment's text")
            top = browser.evaluate(
                "(() => { const d = Array.from(document.querySelectorAll('dt.sig'))"
                ".find(e => /class\\s+DpRerunAllocator/.test(e.innerText));"
                " return d ? d.getBoundingClientRect().top + window.scrollY : null; })()")
            check(top is not None, "C++ allocators page: DpRerunAllocator's declaration")
            # From the header's section: its description, then the class.
            section = browser.evaluate("document.getElementById('ontime-allocators-dp-rerun-hpp')"
                                       ".getBoundingClientRect().top + window.scrollY")
            browser.screenshot(shots / "api-cpp-allocators.png", top=max(0, min(section, top - 300)))

            # The Python reference: ontime.solve with its signature and docstring.
            browser.open(f"{base}/api/python.html")
            text = text_of(browser)
            check("ontime.solve(" in text and "exact optimal success probability" in text,
                  "Python API page: ontime.solve's signature and docstring")
            browser.screenshot(shots / "api-python.png")

            # Search (JavaScript over searchindex.js): DpRerunAllocator finds the C++ page.
            browser.open(f"{base}/search.html?q=DpRerunAllocator",
                         ready="/Search finished|did not match/.test(document.body.innerText)", timeout=60)
            results = browser.evaluate(
                "Array.from(document.querySelectorAll('#search-results ul.search li a'))"
                ".map(a => a.getAttribute('href'))")
            check(any("api/cpp/allocators.html" in r for r in results),
                  f"search for DpRerunAllocator: {len(results)} results, among them api/cpp/allocators.html")
            browser.screenshot(shots / "search.png")
        except AssertionError as failure:
            print(f"docs-browser-test: FAILED: {failure}", file=sys.stderr)
            browser.screenshot(shots / "failure.png")
            return 1
        finally:
            browser.close()
    print(f"docs-browser-test: all checks passed; screenshots in {shots}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
