#!/usr/bin/python3
"""Browser test of driftlab-server's web pages in headless Chromium, driven through chromedriver's
WebDriver protocol (plain HTTP + JSON, urllib).

Usage: web_browser_test.py SERVER_BINARY CLI_BINARY WORK_DIR [--screenshots DIR]
(PYTHONPATH: <build>/python, for the driftlab package and its gRPC modules.)

Starts driftlab-server on 127.0.0.1 (gRPC and --http-port on ephemeral ports, a tokens file, two
jobs at once) and Chromium (Debian's chromium and chromium-driver), then, as a person would:
  1. opens the pages without a session: the sign-in page; signs in with the token;
  2. submits a job through the Python gRPC client and watches its progress rise on the job page
     (several values without a reload), and on the list;
  3. submits a second job and cancels it with the page's button: the gRPC client sees CANCELLED;
  4. opens the finished job's report (every plot drawn, no script error, under the page's
     sandboxing content security policy): its bytes equal `driftlab result` + `driftlab report`
     of the same job; downloads the result with the page's link: the bytes of `driftlab result`;
  5. runs a calibration with `driftlab calibrate --server`: its page and report (the bytes of
     `driftlab report CALIB.json`); opens the IMU catalogue;
  6. with JavaScript off: signs in, lists the jobs and downloads the result.
Screenshots (--screenshots) of each step are written as PNG files. Exit 77 (ctest SKIP) when
chromium or chromedriver is not installed.
"""
import base64
import http.client
import json
import os
import pathlib
import re
import shutil
import socket
import subprocess
import sys
import time
import urllib.parse

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE.parent / "report"))

TOKEN = "web-browser-test-token"
W3C_ELEMENT = "element-6066-11e4-a52e-4f735466cecf"


def fail(message):
    raise SystemExit("FAILED: " + message)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for(predicate, timeout_s, what, interval_s=0.2):
    """Polls predicate() until it returns a true value (bounded by timeout_s)."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(interval_s)
    fail(f"timed out after {timeout_s} s waiting for {what}")


class WebDriver:
    """The few W3C WebDriver commands the test needs, over chromedriver's HTTP port."""

    def __init__(self, port, download_dir, profile_dir, javascript=True):
        self.port = port
        args = ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic",
                "--no-first-run", "--disable-background-networking", "--disable-component-update",
                "--disable-sync", "--disable-dev-shm-usage", "--disable-extensions",
                f"--user-data-dir={profile_dir}", "--window-size=1400,1000"]
        prefs = {"download.default_directory": str(download_dir),
                 "download.prompt_for_download": False,
                 "safebrowsing.enabled": False}
        if not javascript:
            prefs["profile.managed_default_content_settings.javascript"] = 2
        caps = {"capabilities": {"alwaysMatch": {
            "browserName": "chrome",
            "goog:chromeOptions": {"binary": shutil.which("chromium"), "args": args,
                                   "prefs": prefs}}}}
        self.session = self.call("POST", "/session", caps)["sessionId"]
        # Headless Chromium downloads only when told where (Chromium's DevTools command).
        self.call("POST", f"/session/{self.session}/goog/cdp/execute",
                  {"cmd": "Browser.setDownloadBehavior",
                   "params": {"behavior": "allow", "downloadPath": str(download_dir)}})

    def call(self, method, path, body=None):
        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=120)
        data = json.dumps(body).encode() if body is not None else None
        connection.request(method, path, data, {"Content-Type": "application/json"})
        response = connection.getresponse()
        payload = json.loads(response.read() or b"{}")
        connection.close()
        value = payload.get("value")
        if response.status != 200:
            fail(f"WebDriver {method} {path}: {response.status} {json.dumps(value)[:500]}")
        return value

    def s(self, path):
        return f"/session/{self.session}{path}"

    def get(self, url):
        self.call("POST", self.s("/url"), {"url": url})

    def url(self):
        return self.call("GET", self.s("/url"))

    def find(self, css):
        return self.call("POST", self.s("/element"), {"using": "css selector", "value": css})[
            W3C_ELEMENT]

    def click(self, css):
        self.call("POST", self.s(f"/element/{self.find(css)}/click"), {})

    def type(self, css, text):
        self.call("POST", self.s(f"/element/{self.find(css)}/value"), {"text": text})

    def js(self, script, *args):
        return self.call("POST", self.s("/execute/sync"), {"script": script, "args": list(args)})

    def source(self):
        return self.call("GET", self.s("/source"))

    def cookies(self):
        return self.call("GET", self.s("/cookie"))

    def screenshot(self, path):
        if path is None:
            return
        pathlib.Path(path).write_bytes(base64.b64decode(self.call("GET", self.s("/screenshot"))))

    def quit(self):
        self.call("DELETE", self.s(""))


def http_get(port, path, cookie):
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=60)
    connection.request("GET", path, headers={"Cookie": cookie})
    response = connection.getresponse()
    body = response.read()
    connection.close()
    return response.status, dict(response.getheaders()), body


def run(cmd, **kwargs):
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300, **kwargs)
    if proc.returncode != 0:
        fail(f"{' '.join(map(str, cmd))} exited {proc.returncode}\n{proc.stdout}\n{proc.stderr}")
    return proc


def job(name, runs, duration_s):
    return {"name": name, "description": "web browser test job",
            "motion": {"initial": {"lat_deg": 45.07, "lon_deg": 7.69, "height_m": 240.0},
                       "segments": [{"static": {"duration_s": duration_s}}]},
            "rate_hz": 100, "navigation": {"mechanization": "NED"},
            "sensor": {"preset": "tactical"},
            "monte_carlo": {"runs": runs, "seed": 11, "epoch_interval_s": 10.0}}


def main():
    if len(sys.argv) < 4:
        raise SystemExit(__doc__)
    server_binary, cli, work = (os.path.abspath(a) for a in sys.argv[1:4])
    shots = None
    if "--screenshots" in sys.argv:
        shots = pathlib.Path(sys.argv[sys.argv.index("--screenshots") + 1]).resolve()
        shots.mkdir(parents=True, exist_ok=True)

    def shot(name):
        return None if shots is None else shots / f"{name}.png"

    if not shutil.which("chromium") or not shutil.which("chromedriver"):
        print("SKIP: chromium or chromedriver is not installed (Debian packages chromium and "
              "chromium-driver; scripts/ci-packages.sh installs them)")
        return 77
    from driftlab import connect  # noqa: E402 (the package in <build>/python: PYTHONPATH)
    import browser_test  # tests/report/browser_test.py: the tumble recording

    work = pathlib.Path(work)
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    digest = run([server_binary, "hash-token", TOKEN]).stdout.strip()
    (work / "tokens.txt").write_text(f"alice {digest}\n")
    log = open(work / "server.log", "w")
    server = subprocess.Popen(
        [server_binary, "--listen", "127.0.0.1:0", "--data", str(work / "data"), "--tokens",
         str(work / "tokens.txt"), "--port-file", str(work / "port"), "--http-port", "0",
         "--http-port-file", str(work / "http-port"), "--max-concurrent-jobs", "2",
         "--threads-per-job", "1"], stdout=log, stderr=subprocess.STDOUT)
    driver_port = free_port()
    driver_log = open(work / "chromedriver.log", "w")
    chromedriver = subprocess.Popen(["chromedriver", f"--port={driver_port}"],
                                    stdout=driver_log, stderr=subprocess.STDOUT)
    browsers = []
    try:
        wait_for(lambda: (work / "port").exists() or server.poll() is not None, 30,
                 "the server's port file")
        if server.poll() is not None:
            fail("the server exited:\n" + (work / "server.log").read_text())
        grpc_address = f"127.0.0.1:{(work / 'port').read_text().strip()}"
        http_port = int((work / "http-port").read_text())
        base = f"http://127.0.0.1:{http_port}"

        def driver_up():
            try:
                socket.create_connection(("127.0.0.1", driver_port), timeout=1).close()
                return True
            except OSError:
                return False
        wait_for(driver_up, 30, "chromedriver")
        downloads = work / "downloads"
        downloads.mkdir()
        browser = WebDriver(driver_port, downloads, work / "profile")
        browsers.append(browser)

        # 1. No session: the sign-in page. Sign in with the token.
        browser.get(base + "/jobs")
        if not browser.url().endswith("/signin"):
            fail(f"without a session /jobs went to {browser.url()}, not /signin")
        browser.screenshot(shot("1_signin"))
        browser.type("input[name=token]", TOKEN)
        browser.click("form[action='/signin'] button")
        wait_for(lambda: browser.url().endswith("/jobs"), 10, "the job list after signing in")
        print("signed in; the job list is", browser.url())

        # 2. A job submitted through the gRPC client; its progress rises on the job page.
        client = connect(grpc_address, token=TOKEN)
        # A probe job measures this machine's speed, so that the watched job runs about 15 s.
        probe = client.wait(client.submit(job("web_probe", 50, 600.0)), timeout_s=300)
        rate = probe.samples_total / max(probe.elapsed_s, 1e-3)
        runs = int(min(100000, max(50, 15.0 * rate / 60000)))
        print(f"probe: {rate:.3g} samples/s; the watched job gets {runs} runs")
        watched = client.submit(job("web_progress", runs, 600.0))
        cancelled = client.submit(job("web_to_cancel", 30000, 600.0))  # 1.8e9 samples: minutes
        browser.get(base + "/jobs")
        wait_for(lambda: browser.js(
            "return document.querySelectorAll('tbody tr[data-state=RUNNING]').length") >= 1,
            30, "a RUNNING row in the list")
        browser.screenshot(shot("2_job_list_running"))
        browser.get(base + "/jobs/" + watched)
        browser.js("window.driftlabTestMarker = 'no reload';")
        seen = []

        def progress_values():
            state, pct, marker = browser.js(
                "var s = document.querySelector('section.status');"
                "var p = s && s.querySelector('.pct');"
                "return [s ? s.getAttribute('data-state') : null, p ? p.textContent : null,"
                " window.driftlabTestMarker || null];")
            if state == "RUNNING" and marker == "no reload" and pct:
                value = float(pct.replace("%", "").strip())
                if not seen or value != seen[-1]:
                    seen.append(value)
                    if len(seen) == 2:
                        browser.screenshot(shot("3_job_page_progress"))
            return len(seen) >= 3 or state in ("SUCCEEDED", "FAILED", "CANCELLED")
        wait_for(progress_values, 120, "the progress on the job page", interval_s=0.3)
        if len(seen) < 3 or seen != sorted(seen):
            fail(f"the job page showed progress {seen}: not three rising values without reload")
        print("progress on the job page without reload:", seen)

        # 3. Cancel the second job with the page's button.
        browser.get(base + "/jobs/" + cancelled)
        browser.click("form.cancel button")
        wait_for(lambda: "CANCELLED" in browser.js(
            "var s = document.querySelector('section.status'); return s ? s.textContent : '';"),
            30, "CANCELLED on the cancelled job's page")
        state = client.status(cancelled).state
        from driftlab.v1 import service_pb2
        if state != service_pb2.CANCELLED:
            fail(f"after the page's cancel the gRPC client sees state {state}")
        browser.screenshot(shot("4_job_cancelled"))
        print("cancelled from the page:", cancelled)

        # 4. The finished job: its page reloads itself and offers the report and the result.
        client.wait(watched, timeout_s=600)
        browser.get(base + "/jobs/" + watched)
        wait_for(lambda: browser.js("return !!document.querySelector('section.result a');"), 10,
                 "the result section")
        browser.screenshot(shot("5_job_succeeded"))
        run([cli, "result", watched, "--server", grpc_address, "--token", TOKEN, "--out",
             str(work / "cli_result.json")])
        run([cli, "report", str(work / "cli_result.json"), "--out", str(work / "cli_report.html")])
        session = next(c for c in browser.cookies() if c["name"] == "driftlab_session")
        if not session.get("httpOnly"):
            fail("the session cookie is not HttpOnly")
        cookie = f"driftlab_session={session['value']}"
        status, headers, served = http_get(http_port, f"/jobs/{watched}/report.html", cookie)
        if status != 200 or served != (work / "cli_report.html").read_bytes():
            fail(f"the served report ({status}, {len(served)} bytes) differs from `driftlab report`"
                 f" of `driftlab result` ({(work / 'cli_report.html').stat().st_size} bytes)")
        print(f"served report = driftlab report of driftlab result: {len(served)} bytes")
        browser.get(base + f"/jobs/{watched}/report.html")
        plots = wait_for(lambda: browser.js(
            "var all = document.querySelectorAll('.dl-plot');"
            "var drawn = document.querySelectorAll('.dl-plot[data-drawn=yes]');"
            "return all.length > 0 && drawn.length === all.length ? all.length : 0;"), 30,
            "every plot of the report drawn")
        errors = browser.js("return document.documentElement.getAttribute('data-errors');")
        if errors:
            fail("script errors in the served report: " + errors)
        browser.screenshot(shot("6_report"))
        print(f"report in the browser: {plots} plots drawn, no script error")
        browser.get(base + "/jobs/" + watched)
        browser.click("a[href$='/result.json']")
        download = downloads / f"{watched}.json"
        wait_for(download.exists, 30, "the downloaded result")
        if download.read_bytes() != (work / "cli_result.json").read_bytes():
            fail("the downloaded result differs from `driftlab result --out`")
        print(f"downloaded result = driftlab result: {download.stat().st_size} bytes")

        # 5. A calibration through the CLI, then its page and report; the IMU catalogue.
        tumble = work / "tumble.csv"
        browser_test.write_tumble(str(tumble))
        run([cli, "calibrate", "imu", str(tumble), "--lat", "45", "--server", grpc_address,
             "--token", TOKEN, "--out", str(work / "calib.json")])
        run([cli, "report", str(work / "calib.json"), "--out", str(work / "calib_report.html")])
        browser.get(base + "/calibrations")
        browser.screenshot(shot("7_calibrations"))
        browser.click("table.jobs td.name a")
        wait_for(lambda: "/calibrations/cal-" in browser.url(), 10, "the calibration page")
        calibration = browser.url().rsplit("/", 1)[1]
        browser.screenshot(shot("8_calibration"))
        status, _, served = http_get(http_port, f"/calibrations/{calibration}/report.html", cookie)
        if status != 200 or served != (work / "calib_report.html").read_bytes():
            fail("the served calibration report differs from `driftlab report CALIB.json`")
        status, _, served = http_get(http_port, f"/calibrations/{calibration}/result.json", cookie)
        if served != (work / "calib.json").read_bytes():
            fail("the served calibration result differs from `driftlab calibrate --out`")
        print("calibration page, report and result = the CLI's")
        browser.get(base + "/catalog")
        browser.screenshot(shot("9_catalog"))
        browser.click("a[href='/catalog/tactical']")
        wait_for(lambda: "Figures (datasheet units)" in browser.source(), 10,
                 "the preset's figures")
        browser.screenshot(shot("10_preset"))

        # 6. JavaScript off: sign in, the list, a download.
        plain_downloads = work / "downloads_nojs"
        plain_downloads.mkdir()
        plain = WebDriver(driver_port, plain_downloads, work / "profile_nojs", javascript=False)
        browsers.append(plain)
        plain.get(base + "/signin")
        plain.type("input[name=token]", TOKEN)
        plain.click("form[action='/signin'] button")
        wait_for(lambda: plain.url().endswith("/jobs"), 10, "the list without JavaScript")
        source = plain.source()
        if watched not in source or cancelled not in source:
            fail("without JavaScript the list does not show both jobs")
        plain.screenshot(shot("11_list_without_javascript"))
        plain.get(base + "/jobs/" + watched)
        plain.click("a[href$='/result.json']")
        download = plain_downloads / f"{watched}.json"
        wait_for(download.exists, 30, "the download without JavaScript")
        if download.read_bytes() != (work / "cli_result.json").read_bytes():
            fail("the download without JavaScript differs from `driftlab result --out`")
        print("without JavaScript: sign-in, list and download work")
        if server.poll() is not None:
            fail("the server died")
    finally:
        for b in browsers:
            try:
                b.quit()
            except SystemExit:
                pass
        chromedriver.terminate()
        chromedriver.wait(timeout=30)
        server.terminate()
        server.wait(timeout=60)
    print("PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
