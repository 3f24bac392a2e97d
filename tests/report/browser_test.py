#!/usr/bin/python3
"""Browser test of the HTML reports: each report type, written by the CLI, loads in headless
Chromium with no script error and every interactive plot drawn.

Usage: browser_test.py DRIFTLAB_CLI WORK_DIR [--screenshots DIR]
(--screenshots: the first screen of each report, NAME.png, and one plot alone, NAME_plot.png.)

Report types: the Monte-Carlo report (`driftlab run --report`, examples/car_drive_gnss.json cut to
20 runs: GNSS outage and ZUPT shading, NEES plot, scatter), the calibration report
(`driftlab calibrate imu --report` on a tumble written here) and the noise-fit report
(`driftlab export` of a static recording, then `driftlab allan --fit --report`).

Each page is loaded with `chromium --headless --disable-gpu --no-sandbox --dump-dom` after a
virtual-time budget; report_plots.js marks each plot's element data-drawn="yes" when its canvas
holds a non-transparent pixel and records uncaught errors in <html data-errors>. Chromium's
console messages (--enable-logging=stderr) are checked for errors too. Exit 77 (ctest SKIP) when
chromium is not installed.
"""
import os
import re
import shutil
import subprocess
import sys
import json

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def run(cmd, cwd):
    proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=300)
    if proc.returncode != 0:
        raise SystemExit(f"FAILED: {' '.join(cmd)} exited {proc.returncode}\n{proc.stdout}\n"
                         f"{proc.stderr}")
    return proc


def browser(exe, page, work, extra):
    profile = os.path.join(work, "profile")
    cmd = [exe, "--headless", "--disable-gpu", "--no-sandbox", "--no-first-run",
           "--disable-extensions", "--disable-dev-shm-usage", f"--user-data-dir={profile}",
           "--enable-logging=stderr", "--v=0", "--virtual-time-budget=10000",
           "--window-size=1280,900"] + extra + ["file://" + os.path.abspath(page)]
    return subprocess.run(cmd, cwd=work, capture_output=True, text=True, timeout=120)


def rotation(axis, angle):
    """Rotation matrix about body axis 0, 1, 2 by angle [rad] (frame rotation of a vector)."""
    import math
    c, s = math.cos(angle), math.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m = [[1.0 if r == k else 0.0 for k in range(3)] for r in range(3)]
    m[i][i], m[i][j], m[j][i], m[j][j] = c, -s, s, c
    return m


def matmul(a, b):
    return [[sum(a[r][k] * b[k][c] for k in range(3)) for c in range(3)] for r in range(3)]


def write_tumble(path):
    """A 19-pose tumble at 100 Hz (t_s, gx, gy, gz [rad/s], ax, ay, az [m/s^2]): 30 s initial
    pose, then 1 s rotations about a horizontal body axis (90 to 150 deg) and 5 s poses; gravity
    9.806198 m/s^2 (--lat 45), accelerometer scale errors (+500, -300, +200 ppm) and biases
    (0.02, -0.03, 0.01 m/s^2), white noise from a fixed seed."""
    import random
    import math
    rng = random.Random(20)
    rate, g = 100.0, 9.806198  # WGS-84 normal gravity at 45 deg, 0 m
    scale, bias = [5e-4, -3e-4, 2e-4], [0.02, -0.03, 0.01]
    C_b_n = [[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]]
    rows, t = [], 0.0

    def emit(omega):
        nonlocal t
        up = [-C_b_n[2][k] * g for k in range(3)]  # f_b = C_b_n^T (0, 0, -g)
        f = [(1 + scale[k]) * up[k] + bias[k] + rng.gauss(0, 2e-3) for k in range(3)]
        w = [omega[k] + rng.gauss(0, 2e-4) for k in range(3)]
        rows.append(f"{t:.2f},{w[0]:.9g},{w[1]:.9g},{w[2]:.9g},{f[0]:.9g},{f[1]:.9g},{f[2]:.9g}")
        t += 1 / rate

    for _ in range(int(30 * rate)):
        emit([0, 0, 0])
    for p in range(18):
        # About one of the two body axes nearest the horizontal, in turn (a rotation about the
        # vertical would leave the specific force unchanged and merge two poses).
        ups = [abs(C_b_n[2][k]) for k in range(3)]
        axis = sorted(range(3), key=lambda k: (round(ups[k], 3), k))[p % 2]
        angle = math.radians([90, 120, 150, -100, -130][p % 5])
        omega = [0.0, 0.0, 0.0]
        omega[axis] = angle
        step = rotation(axis, angle / rate)
        for _ in range(int(rate)):
            C_b_n = matmul(C_b_n, step)
            emit(omega)
        for _ in range(int(5 * rate)):
            emit([0, 0, 0])
    with open(path, "w") as out:
        out.write("t_s,gx,gy,gz,ax,ay,az\n" + "\n".join(rows) + "\n")


def write_reports(cli, work):
    reports = {}
    job = json.load(open(os.path.join(ROOT, "examples", "car_drive_gnss.json")))
    job["monte_carlo"]["runs"] = 20
    job_path = os.path.join(work, "car_drive_gnss.json")
    json.dump(job, open(job_path, "w"))
    run([cli, "run", job_path, "--out", os.path.join(work, "mc.json"), "--report",
         os.path.join(work, "monte_carlo.html")], work)
    reports["monte_carlo"] = os.path.join(work, "monte_carlo.html")

    calib_csv = os.path.join(work, "tumble.csv")
    write_tumble(calib_csv)
    run([cli, "calibrate", "imu", calib_csv, "--lat", "45", "--out", os.path.join(work, "calib.json"),
         "--report", os.path.join(work, "calibration.html")], work)
    reports["calibration"] = os.path.join(work, "calibration.html")

    static_job = os.path.join(work, "static.json")
    json.dump({"name": "static_stim300", "motion": {"initial": {"lat_deg": 45.0, "lon_deg": 7.0},
               "segments": [{"static": {"duration_s": 1200}}]}, "rate_hz": 100,
               "sensor": {"preset": "stim300"}}, open(static_job, "w"))
    run([cli, "export", static_job, "--out", os.path.join(work, "static_export")], work)
    imu_csv = os.path.join(work, "static_export", "imu.csv")  # with the sensor errors
    if not os.path.exists(imu_csv):
        raise SystemExit("FAILED: driftlab export wrote no imu.csv")
    run([cli, "allan", imu_csv, "--rate", "100", "--fit", "--report",
         os.path.join(work, "noise_fit.html")], work)
    reports["noise_fit"] = os.path.join(work, "noise_fit.html")
    return reports


# The plot each report's second screenshot shows alone (--screenshots).
PLOT_SHOTS = {"monte_carlo": "plot-envelope-position_north_m",
              "calibration": "plot-pose-directions",
              "noise_fit": "plot-allan-f_x_m_per_s2"}


def plot_page(page, plot_id, work):
    """A copy of the report showing only the element plot_id, at the top left."""
    html = open(page, encoding="utf-8").read()
    style = ("<style>body * { visibility: hidden; } #%s, #%s * { visibility: visible; } "
             "#%s { position: fixed; top: 0; left: 0; background: #fff; padding: 8px; }</style>"
             % (plot_id, plot_id, plot_id))
    out = os.path.join(work, os.path.basename(page).replace(".html", "_plot.html"))
    with open(out, "w", encoding="utf-8") as f:
        f.write(html.replace("</head>", style + "</head>", 1))
    return out


def hover_check(exe, page, result_json, work):
    """Hovering the westmost scatter point shows its run index and the simulate command: the
    page is loaded with a script that moves the mouse onto row 0 of the scatter (sorted by east
    error) and copies the tooltip into <html data-hover>."""
    html = open(page, encoding="utf-8").read()
    probe = ("<script>window.addEventListener('load', function () {"
             "var root = document.getElementById('plot-scatter');"
             "var g = root.driftlabGraph, holder = root.querySelector('.dl-graph');"
             "var p = g.toDomCoords(g.getValue(0, 0), g.getValue(0, 1));"
             "var box = holder.getBoundingClientRect();"
             "holder.dispatchEvent(new MouseEvent('mousemove', {clientX: box.left + p[0],"
             " clientY: box.top + p[1], bubbles: true}));"
             "document.documentElement.setAttribute('data-hover',"
             " holder.querySelector('.dl-tip').textContent);"
             # Every toolbar control of one envelope (log x, log y, series, reset), then its PNG.
             "var env = document.getElementById('plot-envelope-position_north_m');"
             # Each checkbox clicked twice (both directions), then reset zoom.
             "env.querySelectorAll('input').forEach(function (c) { c.click(); c.click(); });"
             "env.querySelectorAll('button').forEach(function (c) {"
             " if (c.textContent !== 'PNG') c.click(); });"
             "var url = env.driftlabPngUrl(), box = env.querySelector('.dl-graph');"
             "var blank = document.createElement('canvas');"
             "blank.width = box.clientWidth * (window.devicePixelRatio || 1);"
             "blank.height = box.clientHeight * (window.devicePixelRatio || 1);"
             "var ctx = blank.getContext('2d'); ctx.fillStyle = '#fff';"
             "ctx.fillRect(0, 0, blank.width, blank.height);"
             "document.documentElement.setAttribute('data-png', url.slice(0, 22) + ' ' +"
             " url.length + ' ' + blank.toDataURL('image/png').length);"
             "});</script>")
    out = os.path.join(work, "hover.html")
    with open(out, "w", encoding="utf-8") as f:
        f.write(html.replace("</body>", probe + "</body>", 1))
    dom = browser(exe, out, work, ["--dump-dom"]).stdout
    hover = re.search(r'data-hover="([^"]*)"', dom)
    runs = json.load(open(result_json))["checkpoints"][-1]["runs"]
    west = min(runs, key=lambda r: r["values"][1])  # values[1]: east position error
    want = "driftlab simulate job.json --run %d --out run-%d" % (west.get("run_index", 0),
                                                                  west.get("run_index", 0))
    failures = []
    if not hover or want not in hover.group(1):
        failures.append("monte_carlo: hovering the westmost point does not show '%s' (got %s)"
                        % (want, hover.group(1) if hover else "no tooltip"))
    else:
        print("monte_carlo: hover shows", hover.group(1).replace("\n", " | "))
    # After the toggles: a PNG export at least twice the size of a blank white PNG of the same
    # size (made in the page: lines, bands and labels do not compress to nothing), no script error.
    png = re.search(r'data-png="data:image/png;base64, (\d+) (\d+)"', dom)
    if not png or int(png.group(1)) < 2 * int(png.group(2)):
        failures.append("monte_carlo: PNG export after the toolbar toggles: %s"
                        % (png.group(0) if png else "no data URL"))
    else:
        print("monte_carlo: toolbar toggles done, PNG export %s characters (blank %s)"
              % (png.group(1), png.group(2)))
    errors = re.search(r'data-errors="([^"]*)"', dom)
    if errors:
        failures.append("monte_carlo: script errors after the toolbar toggles: " + errors.group(1))
    return failures


def self_test(exe, work):
    """The checker itself: a page with a script error and a plot that is never drawn fails."""
    page = os.path.join(work, "broken.html")
    with open(page, "w") as f:
        f.write('<!DOCTYPE html><html><head><script>window.addEventListener("error", function (e)'
                ' { document.documentElement.setAttribute("data-errors", e.message); });'
                '</script></head><body><div class="dl-plot" data-drawn="no"></div>'
                '<script>undefinedFunction();</script></body></html>')
    failures = check(exe, "self-test", page, work, quiet=True)
    if len(failures) < 2:
        return ["self-test: a broken page passed the checks: %s" % failures]
    return []


def check(exe, name, page, work, quiet=False):
    html = open(page, encoding="utf-8").read()
    failures = []
    expected = len(re.findall(r'class="dl-plot"', html))
    if expected == 0:
        failures.append(f"{name}: no interactive plot in the report")
    if re.search(r'<(script|link|img)[^>]+(src|href)=', html):
        failures.append(f"{name}: the report loads an external resource")
    proc = browser(exe, page, work, ["--dump-dom"])
    dom = proc.stdout
    if "</html>" not in dom:
        failures.append(f"{name}: chromium returned no DOM (exit {proc.returncode}): "
                        f"{proc.stderr[-2000:]}")
        return failures
    drawn = len(re.findall(r'data-drawn="yes"', dom))
    blank = len(re.findall(r'data-drawn="no"', dom))
    if drawn != expected:
        failures.append(f"{name}: {drawn} of {expected} plots drawn ({blank} blank)")
    errors = re.search(r'data-errors="([^"]*)"', dom)
    if errors:
        failures.append(f"{name}: script errors: {errors.group(1)}")
    for line in proc.stderr.splitlines():
        if "CONSOLE" in line and ("Uncaught" in line or "ERROR" in line.split("CONSOLE")[0]
                                  or "Error" in line):
            failures.append(f"{name}: console: {line}")
    if not quiet:
        print(f"{name}: {drawn}/{expected} plots drawn, {len(html)} bytes")
    return failures


def main():
    if len(sys.argv) < 3:
        raise SystemExit(__doc__)
    cli, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    shots = None
    if "--screenshots" in sys.argv:
        shots = os.path.abspath(sys.argv[sys.argv.index("--screenshots") + 1])
    exe = chromium()
    if exe is None:
        print("SKIP: chromium is not installed (Debian package `chromium`, "
              "scripts/ci-packages.sh installs it)")
        return 77
    os.makedirs(work, exist_ok=True)
    failures = self_test(exe, work)
    reports = write_reports(cli, work)
    failures += hover_check(exe, reports["monte_carlo"], os.path.join(work, "mc.json"), work)
    for name, page in reports.items():
        failures += check(exe, name, page, work)
        if shots:
            os.makedirs(shots, exist_ok=True)
            browser(exe, page, work, [f"--screenshot={os.path.join(shots, name + '.png')}"])
            browser(exe, plot_page(page, PLOT_SHOTS[name], work), work,
                    [f"--screenshot={os.path.join(shots, name + '_plot.png')}"])
    for f in failures:
        print("FAILED:", f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
