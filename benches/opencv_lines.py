"""OpenCV's line detectors on the LLV bench scene, for scale (issue 3).

Times FLD, EDLines and LSD on one core on the same 512² image the LLV
benchmarks use (`tests/it/support/llv_scene.rs`, noise σ 2, seed 42), so that
their figures and `cargo bench --bench llv` come from the same machine:

    pip install opencv-contrib-python-headless
    cargo run --release --example llv_count scene /tmp/scene.pgm
    python3 benches/opencv_lines.py /tmp/scene.pgm

Prints the fastest and the median of N runs (default 200; LSD 50) and the
number of segments each found. Not part of the test suite.
"""

import statistics
import sys
import time

import cv2


def bench(name, detect, runs):
    detect()  # warm-up
    times = []
    for _ in range(runs):
        t = time.perf_counter()
        found = detect()
        times.append(time.perf_counter() - t)
    n = 0 if found is None else len(found)
    print(
        f"{name:8} fastest {min(times) * 1e3:6.3f} ms  "
        f"median {statistics.median(times) * 1e3:6.3f} ms  segments {n}"
    )


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: opencv_lines.py SCENE.pgm [RUNS]")
    img = cv2.imread(sys.argv[1], cv2.IMREAD_GRAYSCALE)
    if img is None:
        sys.exit(f"{sys.argv[1]}: not an image OpenCV can read")
    runs = int(sys.argv[2]) if len(sys.argv) > 2 else 200
    cv2.setNumThreads(1)
    print(f"OpenCV {cv2.__version__}, {img.shape[1]}x{img.shape[0]}, one thread")
    fld = cv2.ximgproc.createFastLineDetector()
    bench("FLD", lambda: fld.detect(img), runs)
    ed = cv2.ximgproc.createEdgeDrawing()

    def edlines():
        ed.detectEdges(img)
        return ed.detectLines()

    bench("EDLines", edlines, runs)
    lsd = cv2.createLineSegmentDetector()
    bench("LSD", lambda: lsd.detect(img)[0], max(runs // 4, 1))


if __name__ == "__main__":
    main()
