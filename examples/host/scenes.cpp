// The scene runner: builds a scene (setup.hpp), steps it to each frame time with the step the
// scene allows (sim.hpp), renders the frames (render.hpp) and prints progress.
#include "scenes.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>

#include "render.hpp"
#include "setup.hpp"

namespace host {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// What a frame shows: a window of the world (2D) or of the projected view (3D).
struct Window {
  double x0, x1, y0, y1;
};

constexpr double kYaw = 0.55, kPitch = 0.38;  // 3D view: yaw about y, then pitch (from above)

void project(const double* x, double* sx, double* sy, double* depth) {
  const double dx = x[0] - 0.5, dy = x[1] - 0.3, dz = x[2] - 0.5;
  const double x1 = std::cos(kYaw) * dx + std::sin(kYaw) * dz, z1 = -std::sin(kYaw) * dx + std::cos(kYaw) * dz;
  *sx = x1;
  *sy = std::cos(kPitch) * dy + std::sin(kPitch) * z1;
  *depth = std::cos(kPitch) * z1 - std::sin(kPitch) * dy;
}

template <int D>
Image render(const Sim<D>& s, const Window& w, int px, const std::function<Rgb(std::size_t)>& colour, Rgb floor_colour,
             bool right_wall) {
  const int W = px, H = static_cast<int>(std::lround(px * (w.y1 - w.y0) / (w.x1 - w.x0)));
  Image img(W, H, {236, 239, 244});
  const double scale = W / (w.x1 - w.x0);
  auto to_px = [&](double sx, double sy, float* X, float* Y) {
    *X = static_cast<float>((sx - w.x0) * scale);
    *Y = static_cast<float>((w.y1 - sy) * scale);
  };
  const double fy = floor_y(s.g.res, s.walls.margin), wx = 1 - fy;
  const double spacing = s.p.n ? std::pow(s.p.v0[0], 1.0 / D) : s.g.h;
  const float r = static_cast<float>(std::max(1.0, 0.65 * scale * spacing));
  if (D == 2) {
    float X, Y;
    to_px(0, fy, &X, &Y);
    img.rect(0, static_cast<int>(Y), W, H, floor_colour);
    if (right_wall) {
      to_px(wx, 0, &X, &Y);
      img.rect(static_cast<int>(X), 0, W, H, {120, 120, 128});
    }
    for (std::size_t k = 0; k < s.p.n; ++k) {
      to_px(s.p.x[D * k], s.p.x[D * k + 1], &X, &Y);
      img.disc(X, Y, r, colour(k));
    }
    return img;
  }
  // 3D: the floor as a grid of lines, the wall as its outline, then z-buffered spheres.
  auto seg = [&](const double* a, const double* b, Rgb c) {
    double sx0, sy0, d0, sx1, sy1, d1;
    project(a, &sx0, &sy0, &d0), project(b, &sx1, &sy1, &d1);
    float X0, Y0, X1, Y1;
    to_px(sx0, sy0, &X0, &Y0), to_px(sx1, sy1, &X1, &Y1);
    img.line(X0, Y0, X1, Y1, c);
  };
  for (int k = 0; k <= 10; ++k) {
    const double t = fy + (1 - 2 * fy) * k / 10.0;
    const double a[3] = {fy, fy, t}, b[3] = {1 - fy, fy, t}, c[3] = {t, fy, fy}, d[3] = {t, fy, 1 - fy};
    seg(a, b, floor_colour), seg(c, d, floor_colour);
  }
  if (right_wall)
    for (int k = 0; k <= 10; ++k) {
      const double t = fy + (1 - 2 * fy) * k / 10.0;
      const double a[3] = {wx, fy, t}, b[3] = {wx, 0.8, t};
      seg(a, b, {150, 150, 158});
    }
  for (std::size_t k = 0; k < s.p.n; ++k) {
    double sx, sy, dep;
    project(&s.p.x[D * k], &sx, &sy, &dep);
    float X, Y;
    to_px(sx, sy, &X, &Y);
    img.disc_z(X, Y, r, static_cast<float>(dep * scale), colour(k));
  }
  return img;
}

struct Scene {
  std::string name, title;
  double duration = 1;
  Window window2, window3;
  Rgb floor_colour{90, 90, 96};
  bool right_wall = false;
};

template <int D>
bool run(const std::string& name, const RunOptions& opt) {
  SceneConfig c;
  c.res = opt.res > 0 ? opt.res : default_res(D);
  c.ppc = opt.ppc;
  Sim<D> s;
  Scene sc;
  sc.name = name;
  std::function<Rgb(std::size_t)> colour;
  char title[200];
  if (name == "ice") {
    build_ice(s, c);
    sc.duration = 3.0;
    sc.window2 = {0.1, 0.9, 0.0, 0.42};
    sc.window3 = {-0.45, 0.45, -0.3, 0.22};
    sc.floor_colour = {170, 60, 40};
    std::snprintf(title, sizeof title,
                  "Ice on a 340 K plate, %dD (blue-white: solid by T, 263..273 K; purple-orange: water by T, 273..340 K)",
                  D);
    const double tm = s.mat.c().melting_point;
    colour = [&s, tm](std::size_t k) {
      if (s.p.ph[k] == AMPM_PHASE_LIQUID) return water_map((s.p.t[k] - tm) / (340 - tm));
      if (s.p.u[k] > 0) return mix({235, 248, 255}, {90, 200, 230}, s.p.u[k] / s.mat.c().latent_heat);
      return ice_map((s.p.t[k] - 263.15) / (tm - 263.15));
    };
  } else if (name == "snowball") {
    build_snowball(s, c);
    sc.duration = 0.5;
    sc.window2 = {0.1, 1.0, 0.0, 0.7};
    sc.window3 = {-0.55, 0.55, -0.3, 0.45};
    sc.right_wall = true;
    std::snprintf(title, sizeof title, "Snowball hits a sticky wall, %dD (colour: J_P, slate 0.6 .. white 1)", D);
    colour = [&s](std::size_t k) { return snow_map((s.p.j_p(k) - 0.6) / 0.4); };
  } else if (name == "elastic-explicit" || name == "elastic-implicit") {
    c.implicit = name == "elastic-implicit";
    build_elastic(s, c);
    sc.duration = 1.0;
    sc.window2 = {0.15, 0.85, 0.0, 0.62};
    sc.window3 = {-0.45, 0.45, -0.3, 0.4};
    std::snprintf(title, sizeof title, "Elastic block dropped, %s stepper, %dD (colour: speed 0..4 m/s)",
                  c.implicit ? "implicit (backward Euler + CG)" : "explicit", D);
    colour = [&s](std::size_t k) {
      double v2 = 0;
      for (int a = 0; a < D; ++a) v2 += s.p.v[D * k + a] * s.p.v[D * k + a];
      return viridis(std::sqrt(v2) / 4);
    };
  } else {
    std::fprintf(stderr, "unknown scene '%s'\n", name.c_str());
    return false;
  }
  if (opt.short_run) sc.duration *= 0.25;
  const int frames = std::max(2, opt.frames);
  std::printf("[%s %dD] %zu particles, %d cells per axis, %.2f s simulated, %d frames, %d threads\n", name.c_str(), D,
              s.p.n, c.res, sc.duration, frames, threads());
  std::fflush(stdout);

  const auto t0 = Clock::now();
  std::vector<Image> shots;
  std::vector<std::string> captions;
  const Window& win = D == 2 ? sc.window2 : sc.window3;
  // Ice: the block's mean temperatures over time.
  std::vector<double> ts, t_all, t_solid, liquid, at_tm;
  std::ofstream csv;
  if (name == "ice") {
    csv.open(opt.out + "/ice_" + std::to_string(D) + "d_temperature.csv");
    csv << "time_s,mean_T_K,mean_T_solid_K,liquid_fraction,fraction_at_T_m,heat_in_J\n";
  }
  long double q_in = 0;
  auto sample = [&]() {
    double sum = 0, sum_s = 0, ns = 0, nl = 0, nm = 0;
    for (std::size_t k = 0; k < s.p.n; ++k) {
      sum += s.p.t[k];
      if (s.p.ph[k] == AMPM_PHASE_SOLID) sum_s += s.p.t[k], ++ns;
      else ++nl;
      nm += s.p.t[k] == s.mat.c().melting_point;
    }
    const double n = static_cast<double>(s.p.n);
    ts.push_back(s.time), t_all.push_back(sum / n), t_solid.push_back(ns > 0 ? sum_s / ns : NAN);
    liquid.push_back(nl / n), at_tm.push_back(nm / n);
    csv << s.time << ',' << sum / n << ',' << (ns > 0 ? sum_s / ns : NAN) << ',' << nl / n << ',' << nm / n << ','
        << static_cast<double>(q_in) << '\n';
  };
  long cg_iterations = 0;
  if (name == "ice") sample();
  for (int f = 0; f < frames; ++f) {
    const double t_frame = sc.duration * f / (frames - 1);
    while (s.time < t_frame - 1e-12) {
      const double dt = s.suggest_dt(t_frame - s.time);
      const StepInfo info = s.step(dt);
      std::string why;
      if (!info.fail.ok() || !s.sane(&why)) {
        std::fprintf(stderr, "[%s %dD] step %ld at t = %.6f s failed: %s %s (particle %zu) %s\n", name.c_str(), D,
                     s.steps, s.time, info.fail.what, status_name(info.fail.status), info.fail.particle, why.c_str());
        return false;
      }
      q_in += info.heat.q_in;
      cg_iterations += info.cg.iterations;
      if (name == "ice" && (s.steps % 50 == 0)) sample();
    }
    Image img = render(s, win, opt.frame_px, colour, sc.floor_colour, sc.right_wall);
    char cap[80];
    std::snprintf(cap, sizeof cap, "t = %.3f s", s.time);
    if (opt.every_frame) write_png(opt.out + "/" + name + "_" + std::to_string(D) + "d_frame" + std::to_string(f) + ".png", img);
    shots.push_back(std::move(img));
    captions.push_back(cap);
    std::printf("[%s %dD] frame %d/%d  t = %.3f s  steps %ld%s  wall %.1f s\n", name.c_str(), D, f + 1, frames, s.time,
                s.steps,
                s.stepper == Stepper::Implicit
                    ? (" (CG " + std::to_string(s.steps ? cg_iterations / s.steps : 0) + " it/step)").c_str()
                    : "",
                seconds_since(t0));
    std::fflush(stdout);
  }
  Image strip = filmstrip(shots, captions, title);
  if (name == "ice") {
    sample();
    const int cw = strip.w / 2 - 6;
    Image a = line_chart(cw, 190, ts, {{t_all, {200, 80, 40}, "mean T, all"}, {t_solid, {40, 90, 200}, "mean T, solid"}},
                         260, 345, s.mat.c().melting_point, "Block temperature (K); dashed: T_m = 273.15 K", "t (s)");
    Image b = line_chart(cw, 190, ts, {{liquid, {30, 120, 220}, "liquid"}, {at_tm, {120, 120, 120}, "at T_m (melting)"}}, 0,
                         1, NAN, "Fraction of particles", "t (s)");
    Image both(strip.w, strip.h + 200, {255, 255, 255});
    both.blit(strip, 0, 0), both.blit(a, 6, strip.h + 4), both.blit(b, cw + 12, strip.h + 4);
    strip = both;
    std::printf("[%s %dD] mean T %.2f K (solid %.2f K), liquid %.1f %%, at T_m %.1f %%, heat in %.4g J\n", name.c_str(), D,
                t_all.back(), t_solid.back(), 100 * liquid.back(), 100 * at_tm.back(), static_cast<double>(q_in));
  }
  const std::string path = opt.out + "/" + name + "_" + std::to_string(D) + "d.png";
  if (!write_png(path, strip)) {
    std::fprintf(stderr, "cannot write %s\n", path.c_str());
    return false;
  }
  std::printf("[%s %dD] wrote %s (%zu particles, %ld steps, %.1f s wall%s)\n", name.c_str(), D, path.c_str(), s.p.n,
              s.steps, seconds_since(t0), s.clamped ? ", SOME PARTICLES CLAMPED" : "");
  return true;
}

}  // namespace

const std::vector<std::string>& scene_names() {
  static const std::vector<std::string> n = {"ice", "snowball", "elastic-explicit", "elastic-implicit"};
  return n;
}

int default_res(int dim) { return dim == 2 ? 64 : 24; }

bool run_scene(const std::string& name, int dim, const RunOptions& opt) {
  return dim == 2 ? run<2>(name, opt) : run<3>(name, opt);
}

}  // namespace host
