// ampm_scenes: the example scenes of examples/README.md.
//
//   ampm_scenes --scene <ice|snowball|elastic-explicit|elastic-implicit|elastic|stepper|all>
//               --dim <2|3|all> [--res CELLS] [--ppc N] [--frames N] [--out DIR] [--short]
//               [--every-frame] [--px PIXELS]
//
// `all` runs every scene and the stepper study (stepper.csv). `elastic` runs both steppers.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <sys/stat.h>
#include <vector>

#include "host/scenes.hpp"

namespace {

void usage() {
  std::printf(
      "usage: ampm_scenes --scene <ice|snowball|elastic-explicit|elastic-implicit|elastic|stepper|all>\n"
      "                   --dim <2|3|all> [--res CELLS] [--ppc N] [--frames N] [--out DIR] [--short]\n"
      "                   [--every-frame] [--px PIXELS]\n"
      "  --res CELLS    grid cells per axis of the unit cube (default 64 in 2D, 24 in 3D);\n"
      "                 larger scenes: e.g. --res 128 (2D) or --res 48 (3D), and/or --ppc 3\n"
      "  --ppc N        particles per cell per axis (default 2)\n"
      "  --frames N     frames in each filmstrip (default 5, the first at t = 0)\n"
      "  --out DIR      output directory (default docs/scenes)\n"
      "  --short        a quarter of each scene's duration (smoke test)\n"
      "  --every-frame  also write every frame as its own PNG\n"
      "  --px PIXELS    width of one frame (default 256)\n");
}

}  // namespace

int main(int argc, char** argv) {
  host::RunOptions opt;
  std::string scene = "all", dim = "2";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--scene") scene = next();
    else if (a == "--dim") dim = next();
    else if (a == "--res") opt.res = std::atoi(next().c_str());
    else if (a == "--ppc") opt.ppc = std::atoi(next().c_str());
    else if (a == "--frames") opt.frames = std::atoi(next().c_str());
    else if (a == "--out") opt.out = next();
    else if (a == "--px") opt.frame_px = std::atoi(next().c_str());
    else if (a == "--short") opt.short_run = true;
    else if (a == "--every-frame") opt.every_frame = true;
    else if (a == "-h" || a == "--help") return usage(), 0;
    else {
      std::fprintf(stderr, "unknown argument %s\n", a.c_str());
      usage();
      return 2;
    }
  }
  std::vector<int> dims;
  if (dim == "2" || dim == "all") dims.push_back(2);
  if (dim == "3" || dim == "all") dims.push_back(3);
  if (dims.empty() || opt.ppc < 1 || opt.frames < 2 || (opt.res != 0 && opt.res < 16)) {
    usage();
    return 2;
  }
  std::vector<std::string> scenes;
  bool study = false;
  if (scene == "all") scenes = host::scene_names(), study = true;
  else if (scene == "elastic") scenes = {"elastic-explicit", "elastic-implicit"};
  else if (scene == "stepper") study = true;
  else scenes = {scene};
  ::mkdir(opt.out.c_str(), 0755);
  bool ok = true;
  for (int d : dims)
    for (const auto& s : scenes) ok = host::run_scene(s, d, opt) && ok;
  if (study) {
    const std::string csv = opt.out + "/stepper.csv";
    for (std::size_t k = 0; k < dims.size(); ++k) ok = host::stepper_study(dims[k], opt, csv, k == 0) && ok;
    if (ok) std::printf("wrote %s\n", csv.c_str());
  }
  return ok ? 0 : 1;
}
