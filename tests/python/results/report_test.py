#!/usr/bin/python3
"""leglab.results.report's pages, opened in headless Chromium.

Usage: report_test.py SOURCE_DIR BIN_DIR OUT_DIR

Makes a small run in OUT_DIR/run (identify with one settle and one record cycle, track with
one warm-up and two measured steps, plot_figures.py) with one sub-run (run/hind: identify on
the hind leg) and a stand-in leg.gif, checks report.py's refusals of bad input, writes the
pages, then drives Chromium over its DevTools protocol (python3-websocket): every page reached
by a link from run/index.html is loaded, and on each
- every image has loaded (complete, naturalWidth > 0),
- every link resolves: a file:// link to an existing file, a #fragment to an element's id,
- nothing was logged as an error (console, uncaught exception, failed load) and nothing was
  requested from outside the folder (no http, no font, no script from a network).
Writes OUT_DIR/index.png, a screenshot of the top page at 1280 x 4000.
Exit 0: passed; 1: failed (every failure printed); 77: skipped, no chromium on PATH.
"""
import base64
import json
import html
import os
import re
import shutil
import subprocess
import sys
import time
import urllib.parse
import urllib.request

PY = "/usr/bin/python3"  # Debian's: plot_figures.py needs its matplotlib
TIMEOUT_S = 30


def run(*command, expect=0):
    result = subprocess.run(command, capture_output=True, text=True, timeout=120)
    if result.returncode != expect:
        sys.exit(f"FAIL: {' '.join(command)} exited {result.returncode} (expected {expect}):\n"
                 f"{result.stdout}{result.stderr}")
    return result


def check_refusals(source, out):
    """report.py on no folder, and on a folder with nothing a program wrote: one line on
    stderr, status 2, nothing written."""
    report = "leglab.results.report"
    empty = os.path.join(out, "empty")
    os.makedirs(os.path.join(empty, "sub"))
    for folder in (os.path.join(out, "no_such_folder"), empty):
        result = run(PY, "-m", report, folder, expect=2)
        if len(result.stderr.strip().splitlines()) != 1 or result.stdout:
            sys.exit(f"FAIL: report.py {folder}: expected one line on stderr, got "
                     f"{result.stdout!r} {result.stderr!r}")
    written = [os.path.join(d, f) for d, _, files in os.walk(empty) for f in files]
    if written:
        sys.exit(f"FAIL: report.py wrote {written} into a folder it refused")


def make_run(source, bin_dir, out):
    top = os.path.join(out, "run")
    quick = ["--set", "identify.settle_cycles=1", "--set", "identify.record_cycles=1"]
    identify = os.path.join(bin_dir, "identify")
    run(identify, "--config", f"{source}/experiments/configs/identify.yaml", "--out", top, *quick)
    run(os.path.join(bin_dir, "track"), "--config", f"{source}/experiments/configs/track.yaml",
        "--out", top, "--set", "warmup_steps=1", "--set", "steps=2")
    run(identify, "--config", f"{source}/experiments/configs/identify.yaml", "--set",
        "robot=ers210a_hind", "--out", os.path.join(top, "hind"), *quick)
    run(PY, "-m", "leglab.results.plot_figures", top)
    run(PY, "-m", "leglab.results.plot_figures", os.path.join(top, "hind"))
    # A stand-in real-servo run (identify's log_fit.json, reduced to what the top page reads):
    # the top page's summary is each motor's mean over held-out logs, here by hand 15, 5, 3.5
    # and 1.5 deg for xl330 (the training log's 100 left out).
    os.makedirs(os.path.join(top, "servo_logs"))
    with open(os.path.join(top, "servo_logs", "log_fit.json"), "w") as f:
        json.dump({"logs": [
            {"role": "validate", "motor": "xl330",
             "mae_deg": {"direct": 10, "best_shift": 4, "paper": 3, "extended": 1}},
            {"role": "validate", "motor": "xl330",
             "mae_deg": {"direct": 20, "best_shift": 6, "paper": 4, "extended": 2}},
            {"role": "train", "motor": "xl330",
             "mae_deg": {"direct": 100, "best_shift": 100, "paper": 100, "extended": 100}}]}, f)
    # A 1x1 GIF where leglab.results.animate writes leg.gif: the page must embed it when present.
    with open(os.path.join(top, "leg.gif"), "wb") as f:
        f.write(base64.b64decode("R0lGODlhAQABAIAAAP///wAAACH5BAEAAAAALAAAAAABAAEAAAICRAEAOw=="))
    run(PY, "-m", "leglab.results.report", top)
    return top


class Browser:
    """Headless Chromium and one page of it, driven over the DevTools protocol."""

    def __init__(self, chromium, profile):
        import websocket  # python3-websocket (scripts/setup.sh)

        self.process = subprocess.Popen(
            [chromium, "--headless=new", "--no-sandbox", "--disable-gpu",
             "--allow-file-access-from-files", "--no-first-run", "--remote-debugging-port=0",
             f"--user-data-dir={profile}", "--window-size=1280,4000", "about:blank"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        # Chromium writes the port it chose into the profile's DevToolsActivePort.
        port_file = os.path.join(profile, "DevToolsActivePort")
        deadline = time.time() + TIMEOUT_S
        while not os.path.exists(port_file) or not open(port_file).read().strip():
            if time.time() > deadline or self.process.poll() is not None:
                raise RuntimeError("chromium did not open its DevTools port")
            time.sleep(0.1)
        port = open(port_file).read().split()[0]
        while True:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list") as reply:
                pages = [t for t in json.load(reply) if t["type"] == "page"]
            if pages or time.time() > deadline:
                break
            time.sleep(0.1)
        self.socket = websocket.create_connection(pages[0]["webSocketDebuggerUrl"],
                                                  timeout=TIMEOUT_S, suppress_origin=True)
        self.next_id = 0
        self.events = []
        for domain in ("Page", "Runtime", "Log", "Network"):
            self.call(f"{domain}.enable")

    def call(self, method, **params):
        self.next_id += 1
        self.socket.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            message = json.loads(self.socket.recv())
            if message.get("id") == self.next_id:
                if "error" in message:
                    raise RuntimeError(f"{method}: {message['error']}")
                return message["result"]
            self.events.append(message)

    def wait_for(self, event):
        for k, message in enumerate(self.events):
            if message.get("method") == event:
                del self.events[k]
                return
        while True:
            message = json.loads(self.socket.recv())
            if message.get("method") == event:
                return
            self.events.append(message)

    def evaluate(self, expression):
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True)
        return result["result"].get("value")

    def close(self):
        try:
            self.call("Browser.close")
        except Exception:  # noqa: BLE001 (closing anyway)
            pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def errors_in(events):
    """The console errors, uncaught exceptions, failed loads and outside requests among the
    protocol's events."""
    found = []
    for message in events:
        method, params = message.get("method"), message.get("params", {})
        if method == "Runtime.consoleAPICalled" and params.get("type") in ("error", "assert"):
            found.append("console: " + " ".join(str(a.get("value", a.get("description", "")))
                                                for a in params.get("args", [])))
        elif method == "Runtime.exceptionThrown":
            found.append("exception: " + params["exceptionDetails"].get("text", ""))
        elif method == "Log.entryAdded" and params["entry"]["level"] == "error":
            found.append(f"log: {params['entry']['text']} {params['entry'].get('url', '')}")
        elif method == "Network.loadingFailed":
            found.append(f"failed load: {params.get('errorText')}")
        elif method == "Network.requestWillBeSent":
            url = params["request"]["url"]
            if not url.startswith(("file:", "data:", "about:")):
                found.append(f"request outside the folder: {url}")
    return found


PAGE_FACTS = """JSON.stringify({
  images: Array.from(document.images).map(i => [i.getAttribute('src'), i.complete,
                                                i.naturalWidth]),
  links: Array.from(document.querySelectorAll('a[href]')).map(a => [a.getAttribute('href'),
                                                                    a.href]),
  ids: Array.from(document.querySelectorAll('[id]')).map(e => e.id),
  height: document.documentElement.scrollHeight})"""


def check_pages(browser, top):
    """Visits every page linked from top's index.html; returns (failures, pages, images)."""
    failures, seen, queue = [], set(), [os.path.join(top, "index.html")]
    images = 0
    while queue:
        path = queue.pop(0)
        if path in seen:
            continue
        seen.add(path)
        url = "file://" + urllib.parse.quote(path)
        browser.events.clear()
        browser.call("Page.navigate", url=url)
        browser.wait_for("Page.loadEventFired")
        facts = json.loads(browser.evaluate(PAGE_FACTS))
        where = os.path.relpath(path, top)
        failures += [f"{where}: {e}" for e in errors_in(browser.events)]
        for src, complete, width in facts["images"]:
            images += 1
            if not complete or width <= 0:
                failures.append(f"{where}: image {src} did not load")
        for raw, absolute in facts["links"]:
            target = urllib.parse.urlsplit(absolute)
            if raw.startswith("#"):
                if raw[1:] not in facts["ids"]:
                    failures.append(f"{where}: link {raw} names no element")
            elif target.scheme != "file":
                failures.append(f"{where}: link {raw} leaves the folder")
            else:
                file = urllib.parse.unquote(target.path)
                if not os.path.isfile(file):
                    failures.append(f"{where}: link {raw} -> {file}: no such file")
                elif file.endswith(".html"):
                    queue.append(os.path.normpath(file))
    return failures, seen, images


def check_findings_first(page):
    """The top page leads with the findings: its tables (Table 1 beside the paper's values,
    Table 2), the real servos' summary, the figures with Fig. 8 first, and the animation; then
    the sub-runs, the configuration and the data files."""
    order = [page.find(f'id="{i}"') for i in
             ("tables", "figures", "animation", "runs", "config", "data")]
    if -1 in order or order != sorted(order):
        sys.exit(f"FAIL: the top page's sections are not findings first: {order}")
    if not page.find("fig8_foot_old_new.png") < page.find("fig1_foot_direct.png") < order[2]:
        sys.exit("FAIL: Fig. 8 is not the top page's first figure")
    cells = re.sub(r"<[^>]+>", " ", page[page.find("Real servos"):order[1]]).split()
    if "xl330 2 15.00 5.00 3.50 1.50".split() not in [cells[k:k + 6] for k in range(len(cells))]:
        sys.exit("FAIL: the top page's real-servo summary is not xl330's held-out means "
                 f"(15.00, 5.00, 3.50, 1.50 deg over 2 logs): {' '.join(cells)[:300]}")


def main(source, bin_dir, out):
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        print("SKIP: chromium is not installed (scripts/setup.sh installs Debian's chromium)")
        return 77
    started = time.time()
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    check_refusals(source, out)
    top = make_run(source, bin_dir, out)
    for expected in ("index.html", "hind/index.html"):
        if not os.path.isfile(os.path.join(top, expected)):
            sys.exit(f"FAIL: report.py wrote no {expected}")
    # The run's config: the keys each program ran with, as it wrote them, on the page.
    with open(os.path.join(top, "index.html")) as f:
        page = f.read()
    for program in ("identify", "track"):
        with open(os.path.join(top, f"{program}_config.yaml")) as f:
            first_key = next(line for line in f if line.strip() and not line.startswith("#"))
        if f"The keys {program} ran with" not in page or html.escape(first_key.strip()) not in page:
            sys.exit(f"FAIL: the page does not show {program}_config.yaml")
    check_findings_first(page)
    made = time.time()
    browser = Browser(chromium, os.path.join(out, "profile"))
    try:
        failures, pages, images = check_pages(browser, top)
        if len(pages) < 2:
            failures.append("the top page links no sub-run page")
        if images < 10:
            failures.append(f"only {images} images on the pages")
        # The top page, as a reader first sees it.
        browser.call("Page.navigate", url="file://" + urllib.parse.quote(f"{top}/index.html"))
        browser.wait_for("Page.loadEventFired")
        browser.call("Emulation.setDeviceMetricsOverride", width=1280, height=4000,
                     deviceScaleFactor=1, mobile=False)
        shot = browser.call("Page.captureScreenshot", format="png")
        with open(os.path.join(out, "index.png"), "wb") as f:
            f.write(base64.b64decode(shot["data"]))
    finally:
        browser.close()
    for failure in failures:
        print("FAIL:", failure)
    print(f"{len(pages)} pages, {images} images checked in {chromium}; run made in "
          f"{made - started:.1f} s, pages checked in {time.time() - made:.1f} s; screenshot "
          f"{os.path.join(out, 'index.png')}")
    return 1 if failures else 0


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    sys.exit(main(*(os.path.abspath(a) for a in sys.argv[1:])))
