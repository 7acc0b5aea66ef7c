// ELSED (Suárez, Buenaposada & Baumela, "ELSED: Enhanced Line SEgment
// Drawing", Pattern Recognition 2022) on the images `vss selftest --export`
// writes, timed in-process on one thread, for benches/opencv_lines.py.
//
// This file is ours; ELSED's own sources are not in this repository. Build
// it against a local checkout of the authors' code (benches/README.md):
//
//   g++ -O3 -DNDEBUG -std=c++14 -I ELSED/src benches/elsed_bench.cpp \
//       ELSED/src/ELSED.cpp ELSED/src/EdgeDrawer.cpp ELSED/src/FullSegmentInfo.cpp \
//       $(pkg-config --cflags --libs opencv4) -o elsed_bench
//
// Usage: elsed_bench RUNS NAME IMAGE.pgm...
// For each image: one warm-up, then RUNS timed detections with the default
// parameters; writes IMAGE-without-.pgm.NAME.seg (x0 y0 x1 y1 a line) and
// prints "IMAGE fastest_ms median_ms RUNS".

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "ELSED.h"

int main(int argc, char **argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s RUNS NAME IMAGE.pgm...\n", argv[0]);
    return 2;
  }
  const int runs = std::max(1, std::atoi(argv[1]));
  const std::string name = argv[2];
  cv::setNumThreads(1);
  upm::ELSED elsed;
  for (int k = 3; k < argc; ++k) {
    const std::string path = argv[k];
    cv::Mat img = cv::imread(path, cv::IMREAD_GRAYSCALE);
    if (img.empty()) {
      std::fprintf(stderr, "%s: not an image OpenCV can read\n", path.c_str());
      return 1;
    }
    upm::Segments segs = elsed.detect(img);  // warm-up
    std::vector<double> ms;
    for (int r = 0; r < runs; ++r) {
      auto t0 = std::chrono::steady_clock::now();
      segs = elsed.detect(img);
      auto t1 = std::chrono::steady_clock::now();
      ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    }
    std::sort(ms.begin(), ms.end());
    // Nearest-rank median, as vss's own times.
    const double median = ms[(ms.size() + 1) / 2 - 1];
    std::string out = path;
    if (out.size() > 4 && out.compare(out.size() - 4, 4, ".pgm") == 0) out.resize(out.size() - 4);
    out += "." + name + ".seg";
    FILE *f = std::fopen(out.c_str(), "w");
    if (!f) {
      std::fprintf(stderr, "%s: cannot write\n", out.c_str());
      return 1;
    }
    std::fprintf(f, "# x0 y0 x1 y1 (ELSED, default parameters)\n");
    for (const upm::Segment &s : segs) std::fprintf(f, "%.6f %.6f %.6f %.6f\n", s[0], s[1], s[2], s[3]);
    std::fclose(f);
    std::printf("%s %.4f %.4f %d\n", path.c_str(), ms.front(), median, runs);
  }
  return 0;
}
