#!/usr/bin/env python3
"""The live view in a real browser: Debian's headless chromium (WebGL through SwiftShader) driven by
python3-selenium and chromium-driver.

One simulated parking-lot drive is calibrated with `rigcal calibrate --view`; the page, opened while it
runs, must load without console errors, draw a canvas that is not blank, show at the end the counters
that report.json holds, and change its picture when the before/after toggle is clicked.

  browser_test.py --rigcal build/apps/rigcal/rigcal [--sanitized 1] [--screenshot FILE.png]

Exit 77 (ctest: skipped) under sanitizer builds, or when the browser packages are missing (a failure
under CI=true).
"""
import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

SKIP = 77


def skip(why):
    if os.environ.get("CI") == "true" and "sanitizer" not in why:
        print(f"FAIL: {why} (CI=true)")
        sys.exit(1)
    print(f"SKIP: {why}")
    sys.exit(SKIP)


def check(cond, what):
    if not cond:
        raise AssertionError(what)
    print(f"ok: {what}")


# Pixel statistics of the WebGL canvas, computed in the page (no image library needed here): the share
# of pixels that differ from the background, the number of distinct colours, and a coarse 64x36
# thumbnail to compare two pictures.
CANVAS_STATS_JS = """
const src = document.getElementById('scene');
const c = document.createElement('canvas');
c.width = src.width; c.height = src.height;
const g = c.getContext('2d');
g.drawImage(src, 0, 0);
const d = g.getImageData(0, 0, c.width, c.height).data;
const bg = [0x11, 0x14, 0x18];
let lit = 0; const colours = new Set();
for (let i = 0; i < d.length; i += 4) {
  if (Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) > 30) lit++;
  if (colours.size < 5000) colours.add((d[i] << 16) | (d[i + 1] << 8) | d[i + 2]);
}
const t = document.createElement('canvas'); t.width = 64; t.height = 36;
const tg = t.getContext('2d'); tg.drawImage(src, 0, 0, 64, 36);
return {lit: lit / (d.length / 4), colours: colours.size, thumb: Array.from(tg.getImageData(0, 0, 64, 36).data)};
"""


def wait_for(predicate, timeout, what):
    until = time.time() + timeout
    while time.time() < until:
        value = predicate()
        if value:
            return value
        time.sleep(0.25)
    raise AssertionError(f"timed out after {timeout} s waiting for {what}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rigcal", required=True)
    ap.add_argument("--sanitized", default="0")
    ap.add_argument("--screenshot", default="")
    ap.add_argument("--duration", default="12")
    args = ap.parse_args()
    if args.sanitized not in ("", "0", "OFF"):
        skip("sanitizer build: the browser tests run in the Release build")
    for exe in ("chromium", "chromedriver"):
        if shutil.which(exe) is None:
            skip(f"{exe} not installed (scripts/install-deps installs chromium chromium-driver)")
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
        from selenium.webdriver.common.by import By
    except ImportError:
        skip("python3-selenium not installed (scripts/install-deps)")

    work = tempfile.mkdtemp(prefix="rigcal-view-browser-")
    proc = None
    driver = None
    try:
        t0 = time.time()
        subprocess.run([args.rigcal, "sim", "--scenario", "parking-lot", "--duration", args.duration, "--out",
                        f"{work}/sim"], check=True, stdout=subprocess.DEVNULL)
        print(f"simulated {args.duration} s of the parking lot in {time.time() - t0:.1f} s")
        err_path = f"{work}/calibrate.err"
        with open(err_path, "w") as err:
            proc = subprocess.Popen([args.rigcal, "calibrate", "--config", f"{work}/sim/rig.yaml", "--pcap",
                                     f"{work}/sim/recording.pcap", "--out", f"{work}/res", "--deadline", "3",
                                     "--view", "127.0.0.1:0", "--view-hold", "120"],
                                    stdout=subprocess.DEVNULL, stderr=err)

        def url():
            m = re.search(r"view: (http://127\.0\.0\.1:\d+/)", open(err_path).read())
            return m.group(1) if m else None

        page = wait_for(url, 30, "the view's URL on stderr")

        opts = webdriver.ChromeOptions()
        opts.binary_location = shutil.which("chromium")
        for a in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--enable-unsafe-swiftshader",
                  "--use-angle=swiftshader", "--window-size=1280,800", "--disable-gpu-sandbox"):
            opts.add_argument(a)
        opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
        driver = webdriver.Chrome(service=Service(shutil.which("chromedriver")), options=opts)
        driver.set_script_timeout(30)
        t_page = time.time()
        driver.get(page)
        check(driver.execute_script("return typeof THREE !== 'undefined' && !!window.rigcalView"),
              "the page loads three.js (Debian's libjs-three) and its script")

        # Live: the map and the trajectory arrive while the run goes on.
        wait_for(lambda: driver.execute_script("return window.rigcalView.poses > 0 && window.rigcalView.mapPoints > 0"),
                 120, "map points and poses")
        # The end: the final counters and the report.
        wait_for(lambda: driver.execute_script(
            "const s = window.rigcalView; return s.report !== null && s.counters !== null && s.counters.finished && "
            "s.cloudPoints.after > 0"), 180, "the finished run's report and clouds")
        print(f"page finished {time.time() - t_page:.1f} s after opening")

        report = json.load(open(f"{work}/res/report.json"))
        shown = {el.get_attribute("data-counter"): el.text for el in driver.find_elements(By.CSS_SELECTOR, "[data-counter]")}
        for key in ("mapping_scans", "keyframes", "lost_frames"):
            check(shown.get(key) == report["input"][key],
                  f"shown {key} {shown.get(key)} equals report.json's {report['input'][key]}")
        lidar_rows = {el.get_attribute("data-lidar"): el.text for el in driver.find_elements(By.CSS_SELECTOR, "[data-lidar]")}
        for lidar in report["lidars"]:
            selected = lidar["evidence"]["frames_selected"]
            check(lidar_rows.get(lidar["sensor"], "").startswith(f"{selected}/"),
                  f"{lidar['sensor']}: shown selection '{lidar_rows.get(lidar['sensor'])}' starts with report's {selected} frames")
        summary = driver.find_element(By.ID, "summary").text
        for lidar in report["lidars"]:
            check(lidar["sensor"] in summary and lidar["verdict"] in summary,
                  f"the summary table names {lidar['sensor']} with its verdict {lidar['verdict']}")

        time.sleep(0.5)  # a few frames with everything drawn
        after = driver.execute_script(CANVAS_STATS_JS)
        check(after["lit"] > 0.01 and after["colours"] > 20,
              f"the canvas is not blank: {100 * after['lit']:.1f}% of pixels drawn, {after['colours']} colours")
        if args.screenshot:
            driver.save_screenshot(args.screenshot)
            print(f"screenshot: {args.screenshot}")
        driver.find_element(By.ID, "toggle").click()
        time.sleep(0.5)
        check(driver.execute_script("return window.rigcalView.showAfter") is False, "the toggle shows the initial guess")
        before = driver.execute_script(CANVAS_STATS_JS)
        changed = sum(1 for a, b in zip(after["thumb"], before["thumb"]) if abs(a - b) > 8) / len(after["thumb"])
        check(changed > 0.005, f"the before/after toggle changes the picture ({100 * changed:.1f}% of the thumbnail)")

        severe = [e for e in driver.get_log("browser") if e.get("level") == "SEVERE"]
        check(not severe, f"no console errors ({severe})")
    finally:
        if driver is not None:
            driver.quit()
        if proc is not None:
            proc.send_signal(signal.SIGINT)  # ends --view-hold
            try:
                code = proc.wait(timeout=30)
                print(f"rigcal calibrate exited {code}")
            except subprocess.TimeoutExpired:
                proc.kill()
                raise AssertionError("rigcal calibrate did not end on SIGINT")
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except AssertionError as e:
        print(f"FAIL: {e}")
        sys.exit(1)
