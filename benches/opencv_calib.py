#!/usr/bin/env python3
"""vss calibrate beside OpenCV's calibrateCamera, on the same views.

The views come from the simulated cell as an operator would take them:
`vss sim --target plate --plate checkerboard` in the background and twelve
`vss grab`s of camera N through the profile's ports (the plate at a new pose
each freeze, noise sigma 2), saved as .img files. Then:

- vss:    `vss calibrate --camera N --plate checkerboard IMAGES` (its own
          grid finder and Weng's model, the centre solved, and again with
          `--centre image`);
- OpenCV: `cv2.findChessboardCornersSB` (8 x 5 inner corners) on each
          image, `cv2.calibrateCamera` with its default model (k1 k2 p1 p2 k3).

Both are held against the camera's true .cdf (profiles/sim/camN.cdf): the
reprojection RMS each reports, f (OpenCV's f = fx * sx and fy * sy, with the
true S) and the centre C.

Run from the repository:  python3 benches/opencv_calib.py [--camera N] [--release]

With `--real DIR` (e.g. ../shared/data/calib-real, 9 x 7 squares) it runs on
real photographs instead: `vss calibrate` (S stated as 0.001 mm/px, so f / sx
is in pixels) against `cv2.findChessboardCorners` + `cornerSubPix` 11 x 11 +
`calibrateCamera` (default model), both with the same cross-validation: two
calibrations from alternate views, each half's views fitted (pose only) with
the other half's intrinsics, the RMS of those held-out errors.

Needs `pip install opencv-contrib-python numpy`.
"""

import argparse
import glob
import os
import re
import signal
import subprocess
import sys
import tempfile

import cv2
import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def read_cdf(path):
    params, name = {}, None
    for line in open(path):
        line = line.strip()
        if "=" in line:
            name = line.split("=")[0]
            params[name] = []
        elif line and name:
            params[name].append([float(v) for v in line.split()])
    return params


def read_img(path):
    """An ITEX .img: 64-byte header, then rows of bytes (formats.md 2)."""
    data = open(path, "rb").read()
    comment = int.from_bytes(data[2:4], "little")
    w = int.from_bytes(data[4:6], "little")
    h = int.from_bytes(data[6:8], "little")
    off = 64 + comment
    return np.frombuffer(data[off:off + w * h], np.uint8).reshape(h, w)


def opencv_held_out(objs, imgs, size):
    """OpenCV's cross-validation, as vss's: alternate halves."""
    errs = []
    halves = [list(range(0, len(objs), 2)), list(range(1, len(objs), 2))]
    for fit, held in [(halves[0], halves[1]), (halves[1], halves[0])]:
        _, k, dist, _, _ = cv2.calibrateCamera([objs[i] for i in fit], [imgs[i] for i in fit], size, None, None)
        for i in held:
            ok, rvec, tvec = cv2.solvePnP(objs[i], imgs[i], k, dist)
            proj, _ = cv2.projectPoints(objs[i], rvec, tvec, k, dist)
            errs.extend(np.linalg.norm(proj.reshape(-1, 2) - imgs[i].reshape(-1, 2), axis=1))
    return float(np.sqrt(np.mean(np.square(errs))))


def real(a, vss):
    paths = sorted(glob.glob(os.path.join(a.real, "*.jpg")),
                   key=lambda p: int(re.sub(r"\D", "", os.path.basename(p)) or 0))
    cols, rows = a.squares
    tmp = tempfile.mkdtemp(prefix="vss-calib-real-")
    plate = os.path.join(tmp, "board.toml")
    open(plate, "w").write(f'kind = "checkerboard"\ncolumns = {cols}\nrows = {rows}\n'
                           f'square = 25.0\norigin = "top-left"\n')
    print(f"{len(paths)} photographs in {a.real}, a checkerboard of {cols} x {rows} squares")
    for extra, label in [([], "vss (default model)"), (["--model", "full"], "vss (--model full)")]:
        out_cdf = os.path.join(tmp, f"vss{len(extra)}.cdf")
        r = subprocess.run([vss, "calibrate", "--plate", plate, "--scale", "0.001,0.001",
                            "--out", out_cdf] + extra + paths, capture_output=True, text=True)
        if r.returncode != 0:
            print(f"{label}: refused: {r.stderr.strip()}")
            continue
        rms = re.search(r"overall: (\d+) corners in (\d+) views, RMS ([\d.]+) px", r.stdout)
        times = re.search(r"grid detection ([\d.]+) ms a view, solution (\d+) ms", r.stdout)
        cv = re.search(r"held-out views RMS ([\d.]+) px", r.stdout)
        got = read_cdf(out_cdf)
        f = got["f"][0][0] / 0.001
        c = (got["C"][0][0], got["C"][1][0])
        print(f"{label:24s} {rms.group(2)} views, RMS {float(rms.group(3)):.4f} px; f {f:.2f} px; "
              f"C {c[0]:.2f} {c[1]:.2f}; held-out RMS {cv.group(1) if cv else '-'} px; "
              f"detection {times.group(1)} ms/view, solution {times.group(2)} ms")
        for line in r.stderr.strip().splitlines():
            print("   ", line)
    pattern = (cols - 1, rows - 1)
    obj = np.zeros((pattern[0] * pattern[1], 3), np.float32)
    obj[:, :2] = np.mgrid[0:pattern[0], 0:pattern[1]].T.reshape(-1, 2)
    objs, imgs, size = [], [], None
    import time
    t0 = time.perf_counter()
    for p in paths:
        g = cv2.imread(p, cv2.IMREAD_GRAYSCALE)
        size = g.shape[::-1]
        ok, corners = cv2.findChessboardCorners(g, pattern)
        if ok:
            corners = cv2.cornerSubPix(g, corners, (11, 11), (-1, -1),
                                       (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 30, 0.001))
            objs.append(obj)
            imgs.append(corners)
    ms = (time.perf_counter() - t0) * 1e3 / max(len(paths), 1)
    t1 = time.perf_counter()
    rms, k, dist, _, _ = cv2.calibrateCamera(objs, imgs, size, None, None)
    solve = (time.perf_counter() - t1) * 1e3
    print(f"{'OpenCV':24s} {len(imgs)} views, RMS {rms:.4f} px; fx {k[0, 0]:.2f} fy {k[1, 1]:.2f}; "
          f"C {k[0, 2]:.2f} {k[1, 2]:.2f}; held-out RMS {opencv_held_out(objs, imgs, size):.4f} px; "
          f"detection {ms:.1f} ms/view, solution {solve:.0f} ms; OpenCV {cv2.__version__}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--camera", type=int, default=1)
    ap.add_argument("--views", type=int, default=12)
    ap.add_argument("--release", action="store_true")
    ap.add_argument("--real", metavar="DIR", help="real photographs (.jpg) of a checkerboard")
    ap.add_argument("--squares", type=int, nargs=2, default=(9, 7), metavar=("COLS", "ROWS"))
    a = ap.parse_args()
    vss = os.path.join(REPO, "target", "release" if a.release else "debug", "vss")
    if a.real:
        return real(a, vss)
    cam = a.camera
    truth = read_cdf(os.path.join(REPO, "profiles", "sim", f"cam{cam}.cdf"))
    sx, sy = truth["S"][0][0], truth["S"][1][0]
    f_true = truth["f"][0][0]
    c_true = (truth["C"][0][0], truth["C"][1][0])
    tmp = tempfile.mkdtemp(prefix="vss-calib-")
    link = os.path.join(tmp, "ttyVSG0")
    cdf = [os.path.join(REPO, "profiles", "sim", f"cam{k}.cdf") for k in range(1, 5)]
    sim = subprocess.Popen(
        [vss, "sim", "--target", "plate", "--plate", "checkerboard", "--link", link],
        stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    sim.stdout.readline()
    relay = sim.stdout.readline().split(": ", 1)[1].strip()
    sim.stdout.readline()
    base = open(os.path.join(REPO, "profiles", "default.toml")).read()
    # The profile's grabber and relay board: the simulator's ports.
    lines = base.split("\n")
    section = None
    for i, line in enumerate(lines):
        if line.startswith("["):
            section = line.strip()
        elif section in ("[grabber]", "[relay]") and line.startswith("kind ="):
            lines[i] = 'kind = "vsg"' if section == "[grabber]" else 'kind = "numato"'
        elif section in ("[grabber]", "[relay]") and line.startswith("port ="):
            lines[i] = f'port = "{link}"' if section == "[grabber]" else f'port = "{relay}"'
    prof = "\n".join(lines)
    prof = re.sub(r'cdf = \[.*\]', "cdf = [" + ", ".join(f'"{c}"' for c in cdf) + "]", prof)
    prof_path = os.path.join(tmp, "cell.toml")
    open(prof_path, "w").write(prof)
    images = []
    try:
        for k in range(1, a.views + 1):
            subprocess.run([vss, "--profile", prof_path, "grab", "--camera", str(cam), "--lighting", "e",
                            "--image", str(k), "--session", os.path.join(tmp, "s", "cal")],
                           check=True, stderr=subprocess.DEVNULL)
            images.append(os.path.join(tmp, "s", "cal", f"cal{k}e.img"))
    finally:
        sim.send_signal(signal.SIGTERM)
        sim.wait()

    print(f"camera {cam}, {len(images)} views of the checkerboard (9 x 6 squares of 30 mm), noise sigma 2")
    print(f"truth: f {f_true:.4f} mm, C {c_true[0]:.2f} {c_true[1]:.2f} px")
    print()
    for extra, label in [([], "vss (C solved)"), (["--centre", "image"], "vss (--centre image)")]:
        out_cdf = os.path.join(tmp, f"vss{len(extra)}.cdf")
        r = subprocess.run([vss, "--profile", prof_path, "calibrate", "--camera", str(cam),
                            "--plate", "checkerboard", "--out", out_cdf] + extra + images,
                           capture_output=True, text=True)
        if r.returncode != 0:
            print(f"{label}: refused: {r.stderr.strip()}")
            continue
        rms = re.search(r"overall: (\d+) corners.*RMS ([\d.]+) px", r.stdout)
        times = re.search(r"grid detection ([\d.]+) ms a view, solution (\d+) ms", r.stdout)
        got = read_cdf(out_cdf)
        f = got["f"][0][0]
        c = (got["C"][0][0], got["C"][1][0])
        print(f"{label:24s} RMS {float(rms.group(2)):.4f} px over {rms.group(1)} corners; "
              f"f {f:.4f} ({100 * (f - f_true) / f_true:+.3f} %); "
              f"C {c[0]:.2f} {c[1]:.2f} (off {np.hypot(c[0] - c_true[0], c[1] - c_true[1]):.2f} px); "
              f"detection {times.group(1)} ms/view, solution {times.group(2)} ms")

    pattern = (8, 5)
    obj = np.zeros((pattern[0] * pattern[1], 3), np.float32)
    obj[:, :2] = np.mgrid[0:pattern[0], 0:pattern[1]].T.reshape(-1, 2) * 30.0
    objs, imgs = [], []
    for path in images:
        g = read_img(path)
        ok, corners = cv2.findChessboardCornersSB(g, pattern, flags=cv2.CALIB_CB_ACCURACY)
        if ok:
            objs.append(obj)
            imgs.append(corners)
    h, w = read_img(images[0]).shape
    rms, k, dist, _, _ = cv2.calibrateCamera(objs, imgs, (w, h), None, None)
    fx, fy = k[0, 0], k[1, 1]
    cx, cy = k[0, 2], k[1, 2]
    f1, f2 = fx * sx, fy * sy
    print(f"{'OpenCV (SB corners)':24s} RMS {rms:.4f} px over {sum(len(i) for i in imgs)} corners "
          f"in {len(imgs)} views; f {f1:.4f} / {f2:.4f} ({100 * (f1 - f_true) / f_true:+.3f} / "
          f"{100 * (f2 - f_true) / f_true:+.3f} %); C {cx:.2f} {cy:.2f} "
          f"(off {np.hypot(cx - c_true[0], cy - c_true[1]):.2f} px); OpenCV {cv2.__version__}")


if __name__ == "__main__":
    sys.exit(main())
