"""The documentation site as a reader sees it: built with ``mkdocs build --strict``, served on
127.0.0.1 and opened in headless Chromium 1280 px wide. Each page must show its images, let wide
tables, code blocks and equations scroll instead of cutting them off, and typeset its math with
the vendored KaTeX (docs/javascripts/katex/; no network: the fonts must come from the site too).

Chromium is Debian's (``apt-get install chromium``; .ci/run installs it), driven through the
Chrome DevTools protocol over ``--remote-debugging-pipe`` (file descriptors 3 and 4), so the test
needs no Python package and no driver. Without Chromium it skips. Screenshots of each page go to
pytest's tmp_path (the whole page, and its first screen), or to ``$ACL_SITE_SCREENSHOTS``;
``$CHROMIUM`` names another binary, and ``ACL_CHROMIUM_STDERR=1`` shows Chromium's own log.
"""

from __future__ import annotations

import base64
import fcntl
import functools
import http.server
import json
import os
import select
import shutil
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parent.parent
WIDTH, HEIGHT = 1280, 900  # the browser's viewport (CSS px)
# The pages a reader opens first, and those that carry the paper's equations.
PAGES = ["index", "results", "grip", "gait", "estimation"]
MATH_PAGES = {"grip", "gait", "estimation"}
TIMEOUT = 60.0  # s: for one DevTools reply, one page load, the math to typeset


def find_chromium() -> str | None:
    """Debian's ``chromium`` (or ``$CHROMIUM``), if installed."""
    candidates = [os.environ.get("CHROMIUM", ""), "chromium", "chromium-browser"]
    for name in filter(None, candidates):
        path = shutil.which(name)
        if path:
            return path
    return None


class DevTools:
    """A headless Chromium and one page of it, driven over the DevTools pipe.

    Chromium reads commands from its file descriptor 3 and writes replies and events to 4, each
    a JSON message ended by a NUL byte.
    """

    def __init__(self, binary: str, profile: Path) -> None:
        to_chrome_r, to_chrome_w = os.pipe()
        from_chrome_r, from_chrome_w = os.pipe()
        # Chromium's ends go to its descriptors 3 and 4 through a small Python trampoline (the
        # subprocess module keeps only the descriptors it passes, under their own numbers). They
        # are first moved above 9, so that neither overwrites the other on the way.
        ends = [fcntl.fcntl(fd, fcntl.F_DUPFD_CLOEXEC, 10) for fd in (to_chrome_r, from_chrome_w)]
        for fd in (to_chrome_r, from_chrome_w):
            os.close(fd)
        args = [
            "--headless",
            "--no-sandbox",  # CI runs as root, where Chromium's sandbox refuses to start
            "--disable-gpu",
            "--disable-dev-shm-usage",
            "--disable-extensions",
            "--disable-background-networking",
            "--disable-component-update",
            "--no-first-run",
            "--no-default-browser-check",
            "--remote-debugging-pipe",
            f"--user-data-dir={profile}",
            f"--window-size={WIDTH},{HEIGHT}",
            "about:blank",
        ]
        trampoline = (
            "import os, sys; "
            f"os.dup2({ends[0]}, 3); os.dup2({ends[1]}, 4); "
            "os.execv(sys.argv[1], sys.argv[1:])"
        )
        self.proc = subprocess.Popen(
            [sys.executable, "-c", trampoline, binary, *args],
            pass_fds=ends,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=None if os.environ.get("ACL_CHROMIUM_STDERR") else subprocess.DEVNULL,
        )
        for fd in ends:
            os.close(fd)
        self._out, self._in = to_chrome_w, from_chrome_r
        self._buffer = b""
        self._events: list[dict[str, Any]] = []
        self._next_id = 0
        self.session: str | None = None
        target = self.call("Target.createTarget", url="about:blank", session=False)["targetId"]
        self.session = self.call(
            "Target.attachToTarget", targetId=target, flatten=True, session=False
        )["sessionId"]
        self.call("Page.enable")
        self.call("Network.enable")
        self.call(
            "Emulation.setDeviceMetricsOverride",
            width=WIDTH,
            height=HEIGHT,
            deviceScaleFactor=1,
            mobile=False,
        )

    def _message(self, deadline: float) -> dict[str, Any]:
        while b"\0" not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self._in], [], [], left)[0]:
                raise TimeoutError("Chromium did not answer over the DevTools pipe")
            chunk = os.read(self._in, 1 << 20)
            if not chunk:
                raise RuntimeError(f"Chromium closed the DevTools pipe (exit {self.proc.poll()})")
            self._buffer += chunk
        raw, self._buffer = self._buffer.split(b"\0", 1)
        return json.loads(raw)

    def call(self, method: str, session: bool = True, **params: Any) -> dict[str, Any]:
        """Send one command and return its result; events that arrive meanwhile are kept."""
        self._next_id += 1
        message: dict[str, Any] = {"id": self._next_id, "method": method, "params": params}
        if session and self.session:
            message["sessionId"] = self.session
        os.write(self._out, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + TIMEOUT
        while True:
            reply = self._message(deadline)
            if reply.get("id") == self._next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply["result"]
            if "method" in reply:
                self._events.append(reply)

    def wait_for(self, event: str) -> dict[str, Any]:
        """The first event of this name since the last navigation (waiting for it if needed)."""
        deadline = time.monotonic() + TIMEOUT
        while True:
            for message in self._events:
                if message["method"] == event:
                    return message
            self._events.append(self._message(deadline))

    def navigate(self, url: str) -> list[dict[str, Any]]:
        """Open ``url`` and wait for its load event. Returns the failed requests (an HTTP status
        of 400 or more, or no response at all)."""
        self._events.clear()
        self.call("Page.navigate", url=url)
        self.wait_for("Page.loadEventFired")
        urls, failed = {}, []
        for message in self._events:
            params = message.get("params", {})
            if message["method"] == "Network.requestWillBeSent":
                urls[params["requestId"]] = params["request"]["url"]
            elif message["method"] == "Network.loadingFailed" and not params.get("canceled"):
                url = urls.get(params["requestId"], params["requestId"])
                failed.append({"url": url, "error": params["errorText"]})
            elif message["method"] == "Network.responseReceived":
                response = params["response"]
                if response["status"] >= 400:
                    failed.append({"url": response["url"], "status": response["status"]})
        self.requests = list(urls.values())
        return failed

    def evaluate(self, expression: str) -> Any:
        """The value of a JavaScript expression (awaited if it is a promise)."""
        result = self.call(
            "Runtime.evaluate", expression=expression, awaitPromise=True, returnByValue=True
        )
        if "exceptionDetails" in result:
            raise RuntimeError(f"JavaScript failed: {result['exceptionDetails']}")
        return result["result"].get("value")

    def screenshot(self, path: Path, full_page: bool) -> None:
        """A PNG of the viewport, or of the whole page 1280 px wide."""
        params: dict[str, Any] = {"format": "png"}
        if full_page:
            size = self.call("Page.getLayoutMetrics")["cssContentSize"]
            height = min(int(size["height"]), 16000)  # Chromium's limit for one capture
            params.update(
                captureBeyondViewport=True,
                clip={"x": 0, "y": 0, "width": WIDTH, "height": height, "scale": 1},
            )
        path.write_bytes(base64.b64decode(self.call("Page.captureScreenshot", **params)["data"]))

    def close(self) -> None:
        try:
            self.call("Browser.close", session=False)
        except (OSError, RuntimeError, TimeoutError):
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        os.close(self._out)
        os.close(self._in)


# Run in the page once it has loaded: waits for the fonts and the math, then measures.
INSPECT = r"""
(async () => {
  const deadline = Date.now() + TIMEOUT_MS;
  const untypeset = () => [...document.querySelectorAll(".arithmatex")]
    .filter((el) => !el.querySelector(".katex"));
  while (untypeset().length && Date.now() < deadline) {
    await new Promise((done) => setTimeout(done, 100));
  }
  await document.fonts.ready;
  const article = document.querySelector("article.md-content__inner") || document.body;
  // The page's main column, between the navigation and the table of contents: what sticks out of
  // it is hidden under the sidebars or past the window's edge.
  const column = (document.querySelector(".md-content") || document.body).getBoundingClientRect();
  const within = (r) => r.left >= column.left - 1 && r.right <= column.right + 1;
  const scrolls = (el) => ["auto", "scroll"].includes(getComputedStyle(el).overflowX);
  const name = (el) => el.tagName.toLowerCase() + ": " + el.textContent.trim().slice(0, 80);
  const clipped = [];
  let scrollable = 0;
  const boxes = article.querySelectorAll("table, pre, pre > code, div.arithmatex");
  for (const el of boxes) {
    // Its own content wider than it: it must scroll itself.
    if (el.scrollWidth > el.clientWidth + 1 && !scrolls(el)) {
      clipped.push({element: name(el), why: "its content is wider and it does not scroll",
                    scrollWidth: el.scrollWidth, clientWidth: el.clientWidth});
      continue;
    }
    if (el.scrollWidth > el.clientWidth + 1) scrollable++;
    // Itself sticking out of the main column: a box inside the column must scroll it.
    if (!within(el.getBoundingClientRect())) {
      let holder = el.parentElement;
      while (holder && holder !== article && !scrolls(holder)) holder = holder.parentElement;
      if (holder && holder !== article && within(holder.getBoundingClientRect())) {
        scrollable++;
      } else {
        clipped.push({element: name(el), why: "sticks out of the page's column, no scrolling box",
                      left: el.getBoundingClientRect().left,
                      right: el.getBoundingClientRect().right,
                      columnLeft: column.left, columnRight: column.right});
      }
    }
  }
  const images = [...document.images].map((img) => ({
    src: img.currentSrc || img.src, complete: img.complete, naturalWidth: img.naturalWidth}));
  const rawMath = [];
  for (const el of document.querySelectorAll(".arithmatex")) {
    const copy = el.cloneNode(true);
    copy.querySelectorAll(".katex-mathml").forEach((m) => m.remove());  // the TeX source
    const text = copy.textContent;
    if (!el.querySelector(".katex") || /\$|\\\(|\\\[/.test(text)) {
      rawMath.push(el.textContent.trim().slice(0, 120));
    }
  }
  const prose = article.cloneNode(true);
  prose.querySelectorAll("pre, code, .katex-mathml").forEach((el) => el.remove());
  const proseText = prose.textContent;
  const katexFonts = [...document.fonts].filter((f) => f.family.replace(/"/g, "")
    .startsWith("KaTeX_"));
  return {
    title: document.title,
    clipped, scrollable, images, rawMath,
    strayDelimiters: ["$$", "\\(", "\\["].filter((d) => proseText.includes(d)),
    math: document.querySelectorAll(".arithmatex").length,
    katex: document.querySelectorAll(".arithmatex .katex").length,
    katexErrors: [...document.querySelectorAll(".katex-error")].map((e) => e.textContent),
    fontsLoaded: katexFonts.filter((f) => f.status === "loaded").map((f) => f.family),
    fontsFailed: katexFonts.filter((f) => f.status === "error").map((f) => f.family),
    width: document.documentElement.clientWidth,
    pageScrollWidth: document.documentElement.scrollWidth,
  };
})()
""".replace("TIMEOUT_MS", str(int(TIMEOUT * 1000)))


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: Any) -> None:
        pass


@pytest.fixture(scope="module")
def chromium() -> str:
    binary = find_chromium()
    if binary is None:
        pytest.skip("Chromium is not installed (apt-get install chromium; .ci/run installs it)")
    return binary


@pytest.fixture(scope="module")
def served_site(chromium: str, built_site: Path) -> Iterator[str]:
    """The site, built with ``mkdocs build --strict`` (conftest.built_site), at an
    http://127.0.0.1 address (file:// would not do: Chromium refuses web fonts and workers to
    file:// pages)."""
    site_dir = built_site
    handler = functools.partial(_QuietHandler, directory=str(site_dir))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()
        thread.join(timeout=10)


@pytest.fixture(scope="module")
def browser(chromium: str, tmp_path_factory: pytest.TempPathFactory) -> Iterator[DevTools]:
    try:
        devtools = DevTools(chromium, tmp_path_factory.mktemp("chromium-profile"))
    except (OSError, RuntimeError, TimeoutError) as error:
        pytest.skip(f"Chromium ({chromium}) did not start headless: {error}")
    try:
        yield devtools
    finally:
        devtools.close()


@pytest.fixture(scope="module")
def screenshots(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = os.environ.get("ACL_SITE_SCREENSHOTS")
    if folder:
        Path(folder).mkdir(parents=True, exist_ok=True)
        return Path(folder)
    return tmp_path_factory.mktemp("screenshots")


@pytest.mark.parametrize("page", PAGES)
def test_page_in_chromium(
    page: str, served_site: str, browser: DevTools, screenshots: Path
) -> None:
    url = f"{served_site}/" if page == "index" else f"{served_site}/{page}/"
    failed = browser.navigate(url)
    report = browser.evaluate(INSPECT)
    browser.screenshot(screenshots / f"{page}.png", full_page=True)
    browser.screenshot(screenshots / f"{page}_top.png", full_page=False)
    detail = json.dumps(report, indent=1)[:4000]

    assert WIDTH - 20 <= report["width"] <= WIDTH, detail  # 1280 px, less a scrollbar
    assert not failed, f"requests that failed on {url}: {failed}"
    outside = [r for r in browser.requests if not r.startswith((served_site, "data:", "blob:"))]
    assert not outside, f"{url} loads from outside the site (offline it would not): {outside}"
    broken = [img for img in report["images"] if not img["complete"] or img["naturalWidth"] <= 0]
    assert not broken, f"broken images on {url}: {broken}"
    assert not report["clipped"], f"cut-off tables or code on {url}: {report['clipped']}"
    assert report["pageScrollWidth"] <= report["width"], f"the page scrolls sideways: {detail}"

    assert report["katex"] == report["math"], f"math left untypeset on {url}: {report['rawMath']}"
    assert not report["rawMath"], f"raw TeX in the math of {url}: {report['rawMath']}"
    assert not report["katexErrors"], f"KaTeX could not parse on {url}: {report['katexErrors']}"
    assert not report["strayDelimiters"], f"math delimiters in the text of {url}: {detail}"
    if page in MATH_PAGES:
        assert report["math"] > 0, f"no typeset math on {url}"
        assert report["fontsLoaded"], f"no KaTeX font loaded on {url} (offline?): {detail}"
    assert not report["fontsFailed"], f"KaTeX fonts that failed on {url}: {report['fontsFailed']}"
