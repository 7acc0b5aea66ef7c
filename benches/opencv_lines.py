"""vss beside OpenCV's line detectors (FLD, EDLines, LSD) and, when built,
ELSED: the same images, the same run, the same scorer, one thread each.

    pip install opencv-contrib-python-headless
    cargo build --release
    python3 benches/opencv_lines.py compare [--elsed /work/peers/elsed_bench]

`compare` does, in one run:
1. `vss selftest --export DIR`: both families of synthetic scenes (cubes at
   noise σ 2, 5, 10; yard at σ 0, 2, 5, 10 and signal-dependent) as PGM,
   their truth, and vss's segments, vss timed in-process (warm workspace,
   fastest and median of RUNS per image);
2. FLD, EDLines and LSD (default parameters) on every image in this
   process, one thread (cv2.setNumThreads(1)), fastest and median of RUNS
   per image after one warm-up; their segments and times beside vss's;
3. the ELSED driver (benches/elsed_bench.cpp, built as benches/README.md
   says) on the same images, if --elsed names it;
4. `vss selftest --score DIR`: every detector scored by vss's scorer (same
   matching rule, don't-care edges), one table per family and noise level;
   the JSON goes to DIR/scores.json.

Options: --vss BIN (default target/release/vss), --dir DIR (default
/tmp/vss-compare), --scenes N (12), --size N (512), --runs N (20),
--family cubes|yard|all (all), --skip-export (reuse DIR's images, re-run
the peers and the scoring), --rounds K (1: time vss and the peers K times
in turn and keep each image's fastest, for a shared machine whose speed
drifts while the run goes on).

The older use, timing the three on one image, still works:

    cargo run --release --example llv_count scene /tmp/scene.pgm
    python3 benches/opencv_lines.py /tmp/scene.pgm [RUNS]

Not part of the test suite.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import cv2

try:
    import pytlsd
except ImportError:  # pytlsd is optional: `pip install pytlsd`
    pytlsd = None


def detectors():
    """The OpenCV detectors, each a function from image to an (N, 4) list."""
    fld = cv2.ximgproc.createFastLineDetector()
    ed = cv2.ximgproc.createEdgeDrawing()
    lsd = cv2.createLineSegmentDetector()

    def edlines(img):
        ed.detectEdges(img)
        return ed.detectLines()

    dets = [
        ("FLD", fld.detect),
        ("EDLines", edlines),
        ("LSD", lambda img: lsd.detect(img)[0]),
    ]
    if pytlsd is not None:
        # pytlsd is the authors' LSD in C: the image's pixel (0, 0) over
        # [0, 1]^2 (checked on the photographs: scored with vss's convention
        # its segments lie 0.5 px off). Shifted to pixel centres at whole
        # coordinates, as every other file here.
        dets.append(("pytlsd", lambda img: tlsd(img)))
    return dets


def tlsd(img):
    found = pytlsd.lsd(img.astype("float64"))
    if found is None or len(found) == 0:
        return []
    return [tuple(float(v) - 0.5 for v in s[:4]) for s in found]


def timed(detect, img, runs):
    detect(img)  # warm-up
    times = []
    found = None
    for _ in range(max(runs, 1)):
        t = time.perf_counter()
        found = detect(img)
        times.append((time.perf_counter() - t) * 1e3)
    times.sort()
    # Nearest-rank median, as vss's own times.
    return found, times[0], times[(len(times) + 1) // 2 - 1]


def rows(found):
    if found is None:
        return []
    if isinstance(found, list):
        return found
    return [tuple(float(v) for v in s.reshape(-1)[:4]) for s in found]


def write_segments(path, name, segs):
    with open(path, "w") as f:
        f.write(f"# x0 y0 x1 y1 ({name}, OpenCV {cv2.__version__}, default parameters)\n")
        for s in segs:
            f.write("%.6f %.6f %.6f %.6f\n" % s)


def level_dirs(root):
    with open(os.path.join(root, "manifest.json")) as f:
        manifest = json.load(f)
    for fam in manifest["families"]:
        for level in fam["levels"]:
            d = os.path.join(root, fam["name"], level)
            stems = [f"s{i:02d}" for i in range(fam["scenes"])]
            yield fam["name"], level, d, stems


def run_peers(root, runs, elsed):
    dets = detectors()
    for family, level, d, stems in level_dirs(root):
        times = {name: [] for name, _ in dets}
        for stem in stems:
            pgm = os.path.join(d, stem + ".pgm")
            img = cv2.imread(pgm, cv2.IMREAD_GRAYSCALE)
            if img is None:
                sys.exit(f"{pgm}: not an image OpenCV can read; run the export again")
            for name, detect in dets:
                found, fastest, median = timed(detect, img, runs)
                write_segments(os.path.join(d, f"{stem}.{name}.seg"), name, rows(found))
                times[name].append((stem, fastest, median))
        for name, t in times.items():
            with open(os.path.join(d, f"{name}.times"), "w") as f:
                f.write(f"# scene fastest_ms median_ms runs ({name}, in-process, one thread)\n")
                for stem, fastest, median in t:
                    f.write(f"{stem} {fastest:.4f} {median:.4f} {runs}\n")
        if elsed:
            pgms = [os.path.join(d, s + ".pgm") for s in stems]
            out = subprocess.run(
                [elsed, str(runs), "ELSED", *pgms], check=True, capture_output=True, text=True
            ).stdout
            with open(os.path.join(d, "ELSED.times"), "w") as f:
                f.write("# scene fastest_ms median_ms runs (ELSED, C++, in-process, one thread)\n")
                for line in out.splitlines():
                    path, fastest, median, n = line.split()
                    stem = os.path.basename(path)[: -len(".pgm")]
                    f.write(f"{stem} {fastest} {median} {n}\n")
        print(f"{family}/{level}: peers done", file=sys.stderr)


def keep_fastest(root, best):
    """Folds this round's times files into `best` (per file and scene, the
    smallest fastest and median so far) and writes the files back with them:
    rounds alternate vss and its peers, so a slow spell of a shared machine
    lands on each of them in some round and not on the figure kept."""
    for dirpath, _, files in os.walk(root):
        for name in files:
            if not name.endswith(".times"):
                continue
            path = os.path.join(dirpath, name)
            with open(path) as f:
                lines = f.read().splitlines()
            head = [l for l in lines if l.startswith("#")]
            kept = best.setdefault(path, {})
            for line in lines:
                if line.startswith("#") or not line.strip():
                    continue
                # vss's real-photograph times carry its stages' times after
                # the runs (kept from the round with the fastest run).
                stem, fastest, median, n, *stages = line.split()
                old = kept.get(stem)
                fastest, median = float(fastest), float(median)
                if old and old[0] <= fastest:
                    stages = old[3]
                if old:
                    fastest, median = min(fastest, old[0]), min(median, old[1])
                kept[stem] = (fastest, median, n, stages)
            with open(path, "w") as f:
                f.write("\n".join(head) + "\n")
                for stem, (fastest, median, n, stages) in kept.items():
                    f.write(" ".join([stem, f"{fastest:.4f}", f"{median:.4f}", n, *stages]) + "\n")


def compare(argv):
    p = argparse.ArgumentParser(prog="opencv_lines.py compare")
    p.add_argument("--vss", default="target/release/vss")
    p.add_argument("--dir", default="/tmp/vss-compare")
    p.add_argument("--scenes", type=int, default=12)
    p.add_argument("--size", type=int, default=512)
    p.add_argument("--runs", type=int, default=20)
    p.add_argument("--family", default="all")
    p.add_argument("--elsed", default=None, help="the ELSED driver (benches/elsed_bench.cpp)")
    p.add_argument("--skip-export", action="store_true")
    p.add_argument("--rounds", type=int, default=1,
                   help="time everything this many times, alternating, and keep each image's fastest")
    a = p.parse_args(argv)
    cv2.setNumThreads(1)
    print(f"OpenCV {cv2.__version__}, one thread; vss {a.vss}", file=sys.stderr)
    best = {}
    for r in range(max(a.rounds, 1)):
        if not a.skip_export:
            subprocess.run(
                [a.vss, "selftest", "--export", a.dir, "--family", a.family,
                 "--scenes", str(a.scenes), "--size", str(a.size), "--runs", str(a.runs)],
                check=True,
            )
        run_peers(a.dir, a.runs, a.elsed)
        keep_fastest(a.dir, best)
        if a.rounds > 1:
            print(f"round {r + 1} of {a.rounds} done", file=sys.stderr)
    table = subprocess.run([a.vss, "selftest", "--score", a.dir], check=True,
                           capture_output=True, text=True).stdout
    print(table, end="")
    scores = subprocess.run([a.vss, "selftest", "--score", a.dir, "--json"], check=True,
                            capture_output=True, text=True).stdout
    with open(os.path.join(a.dir, "scores.json"), "w") as f:
        f.write(scores)


def real(argv):
    """Every detector on a folder of photographs with `NAME_gt.txt` files,
    scored by vss's real-photograph scorer (`vss selftest --score-real`)."""
    p = argparse.ArgumentParser(prog="opencv_lines.py real")
    p.add_argument("--photos", default="../shared/data/yud-tune")
    p.add_argument("--vss", default="target/release/vss")
    p.add_argument("--dir", default="/tmp/vss-real")
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--elsed", default=None, help="the ELSED driver (benches/elsed_bench.cpp)")
    p.add_argument("--rounds", type=int, default=1,
                   help="time everything this many times, alternating, and keep each image's fastest")
    p.add_argument("--skip-vss", action="store_true", help="reuse DIR's vss segments and times")
    p.add_argument("--profile", default=None,
                   help="vss's profile (a .toml file; default: the built-in one)")
    p.add_argument("--bootstrap", type=int, default=0, metavar="N",
                   help="resample the photographs N times: how likely each goal holds on "
                        "another set of as many photographs (see bootstrap())")
    p.add_argument("--skip-run", action="store_true",
                   help="run nothing: score (and bootstrap) the segments already in DIR")
    a = p.parse_args(argv)
    cv2.setNumThreads(1)
    os.makedirs(a.dir, exist_ok=True)
    photos = sorted(
        f for f in os.listdir(a.photos)
        if f.lower().endswith((".jpg", ".jpeg", ".png", ".pgm"))
        and os.path.exists(os.path.join(a.photos, os.path.splitext(f)[0] + "_gt.txt"))
    )
    if not photos:
        sys.exit(f"{a.photos}: no photographs with NAME_gt.txt beside them")
    print(f"OpenCV {cv2.__version__}, one thread; vss {a.vss}; {len(photos)} photographs",
          file=sys.stderr)
    best = {}
    for r in range(0 if a.skip_run else max(a.rounds, 1)):
        if not a.skip_vss:
            prof = ["--profile", a.profile] if a.profile else []
            subprocess.run([a.vss, *prof, "selftest", "--export-real", a.photos, "--dir", a.dir,
                            "--runs", str(a.runs)], check=True)
        dets = detectors()
        times = {name: [] for name, _ in dets}
        for f in photos:
            stem = os.path.splitext(f)[0]
            img = cv2.imread(os.path.join(a.photos, f), cv2.IMREAD_GRAYSCALE)
            if img is None:
                sys.exit(f"{f}: not an image OpenCV can read")
            for name, detect in dets:
                found, fastest, median = timed(detect, img, a.runs)
                write_segments(os.path.join(a.dir, f"{stem}.{name}.seg"), name, rows(found))
                times[name].append((stem, fastest, median))
        for name, t in times.items():
            with open(os.path.join(a.dir, f"{name}.times"), "w") as out:
                out.write(f"# photo fastest_ms median_ms runs ({name}, in-process, one thread)\n")
                for stem, fastest, median in t:
                    out.write(f"{stem} {fastest:.4f} {median:.4f} {a.runs}\n")
        if a.elsed:
            # The driver writes IMAGE.ELSED.seg beside the image (less a
            # .pgm): links in DIR/img keep the photographs' folder untouched.
            img_dir = os.path.join(a.dir, "img")
            os.makedirs(img_dir, exist_ok=True)
            links = []
            for f in photos:
                link = os.path.join(img_dir, f)
                if not os.path.lexists(link):
                    os.symlink(os.path.abspath(os.path.join(a.photos, f)), link)
                links.append(link)
            out = subprocess.run([a.elsed, str(a.runs), "ELSED", *links], check=True,
                                 capture_output=True, text=True).stdout
            with open(os.path.join(a.dir, "ELSED.times"), "w") as t:
                t.write("# photo fastest_ms median_ms runs (ELSED, C++, in-process, one thread)\n")
                for line in out.splitlines():
                    path, fastest, median, n = line.split()
                    stem = os.path.splitext(os.path.basename(path))[0]
                    os.replace(path + ".ELSED.seg", os.path.join(a.dir, f"{stem}.ELSED.seg"))
                    t.write(f"{stem} {fastest} {median} {n}\n")
        keep_fastest(a.dir, best)
        if a.rounds > 1:
            print(f"round {r + 1} of {a.rounds} done", file=sys.stderr)
    cmd = [a.vss, "selftest", "--score-real", a.photos, "--dir", a.dir]
    print(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout, end="")
    scores = subprocess.run(cmd + ["--json"], check=True, capture_output=True, text=True).stdout
    with open(os.path.join(a.dir, "scores.json"), "w") as f:
        f.write(scores)
    if a.bootstrap > 0:
        bootstrap(a, photos)


def bootstrap(a, photos):
    """How likely the issue's goals on photographs hold on another set of
    as many photographs like these (a hold-out): each photograph scored
    alone by vss's scorer (a copy of it and its truth in a folder of its
    own), then the set resampled with replacement `a.bootstrap` times and
    the pooled figures made again from the per-photograph sums."""
    import random
    import shutil
    import tempfile
    per = {}  # detector -> list of per-photograph sums
    with tempfile.TemporaryDirectory() as tmp:
        for f in photos:
            stem = os.path.splitext(f)[0]
            one = os.path.join(tmp, stem)
            os.makedirs(one)
            for name in (f, stem + "_gt.txt"):
                shutil.copyfile(os.path.join(a.photos, name), os.path.join(one, name))
            out = subprocess.run([a.vss, "selftest", "--score-real", one, "--dir", a.dir,
                                  "--json"], check=True, capture_output=True, text=True).stdout
            for x in json.loads(out):
                m, b = x["metrics"], x["by_contrast"]
                per.setdefault(x["detector"], []).append((
                    m["precision"] * m["detected_length"], m["detected_length"],
                    m["recall"] * m["truth_length"], m["truth_length"],
                    b["found"][3], b["truth"][3], b["unmatched"][0] + b["unmatched"][1]))

    def pooled(rows):
        s = [sum(r[k] for r in rows) for k in range(7)]
        prec, rec = s[0] / s[1], s[2] / s[3]
        return 2 * prec * rec / (prec + rec), s[4] / s[5], s[6] / len(rows)

    rng = random.Random(1)
    n = len(photos)
    first, rec40, flat_below, every = 0, [], 0, 0
    for _ in range(a.bootstrap):
        pick = [rng.randrange(n) for _ in range(n)]
        got = {d: pooled([rows[i] for i in pick]) for d, rows in per.items()}
        top = all(got["vss"][0] > g[0] for d, g in got.items() if d != "vss")
        flat = "LSD" in got and got["vss"][2] < got["LSD"][2]
        first += top
        rec40.append(got["vss"][1])
        flat_below += flat
        every += top and flat and got["vss"][1] >= 0.85
    rec40.sort()
    q = lambda p: rec40[min(int(p * len(rec40)), len(rec40) - 1)]
    k = a.bootstrap
    print(f"bootstrap: {k} resamples of the {n} photographs (seed 1)")
    print(f"  F above every peer: {first / k:.3f} of them")
    print(f"  recall at >= 40 grey levels: 5 / 50 / 95 % {q(0.05):.3f} / {q(0.5):.3f} / "
          f"{q(0.95):.3f}; >= 0.85 in {sum(r >= 0.85 for r in rec40) / k:.3f}")
    if "LSD" in per:
        print(f"  false lines on flat structure below LSD's: {flat_below / k:.3f}")
        print(f"  all three at once (F first, recall at >= 40 >= 0.85, flat below LSD's): "
              f"{every / k:.3f}")


def bench(name, detect, runs):
    found, fastest, median = timed(detect, bench.img, runs)
    n = 0 if found is None else len(found)
    print(f"{name:8} fastest {fastest:6.3f} ms  median {median:6.3f} ms  segments {n}")


def one_image(argv):
    img = cv2.imread(argv[0], cv2.IMREAD_GRAYSCALE)
    if img is None:
        sys.exit(f"{argv[0]}: not an image OpenCV can read")
    runs = int(argv[1]) if len(argv) > 1 else 200
    cv2.setNumThreads(1)
    print(f"OpenCV {cv2.__version__}, {img.shape[1]}x{img.shape[0]}, one thread")
    bench.img = img
    for name, detect in detectors():
        bench(name, detect, max(runs // 4, 1) if name == "LSD" else runs)


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: opencv_lines.py compare|real [OPTIONS] | opencv_lines.py SCENE.pgm [RUNS]")
    if sys.argv[1] == "compare":
        compare(sys.argv[2:])
    elif sys.argv[1] == "real":
        real(sys.argv[2:])
    else:
        one_image(sys.argv[1:])


if __name__ == "__main__":
    main()
