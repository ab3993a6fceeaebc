// The scenes of ampm_scenes (ice, snowball, elastic-explicit, elastic-implicit) and the
// explicit-versus-implicit stepper study. Each scene writes <out>/<scene>_<d>d.png, a filmstrip
// of `frames` frames (the ice scene adds its temperature chart and a CSV of the block's mean
// temperature over time).
#pragma once

#include <string>
#include <vector>

namespace host {

struct RunOptions {
  int res = 0;             // cells per axis (0: the default of the scene and dimension)
  int ppc = 2;             // particles per cell per axis
  int frames = 5;          // frames in the filmstrip (first at t = 0)
  bool short_run = false;  // a fraction of the duration (smoke test)
  bool every_frame = false;  // also write each frame as its own PNG
  int frame_px = 256;      // pixels per frame side
  std::string out = "docs/scenes";
};

/// The scene names run_scene accepts, in the order `--scene all` runs them.
const std::vector<std::string>& scene_names();

/// Runs one scene in 2D or 3D and writes its PNG(s); false (with a message) on failure.
bool run_scene(const std::string& name, int dim, const RunOptions& opt);

/// Measures the largest stable Δt and the cost per simulated second of each stepper on the
/// elastic drop, appends rows to `csv` (written with its header when `write_header`).
bool stepper_study(int dim, const RunOptions& opt, const std::string& csv, bool write_header);

/// Default cells per axis of a scene.
int default_res(int dim);

}  // namespace host
