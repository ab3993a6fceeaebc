#include "render.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include "stb_image_write.h"
#include "stb_easy_font.h"

namespace host {

Image::Image(int width, int height, Rgb bg) : w(width), h(height), px(3 * static_cast<std::size_t>(width) * height) {
  for (std::size_t k = 0; k < px.size(); k += 3) px[k] = bg.r, px[k + 1] = bg.g, px[k + 2] = bg.b;
}

void Image::set(int x, int y, Rgb c) {
  if (x < 0 || y < 0 || x >= w || y >= h) return;
  const std::size_t k = 3 * (static_cast<std::size_t>(y) * w + x);
  px[k] = c.r, px[k + 1] = c.g, px[k + 2] = c.b;
}

void Image::rect(int x0, int y0, int x1, int y1, Rgb c) {
  for (int y = std::max(0, y0); y < std::min(h, y1); ++y)
    for (int x = std::max(0, x0); x < std::min(w, x1); ++x) set(x, y, c);
}

void Image::disc(float cx, float cy, float r, Rgb c) {
  const int x0 = static_cast<int>(std::floor(cx - r)), x1 = static_cast<int>(std::ceil(cx + r));
  const int y0 = static_cast<int>(std::floor(cy - r)), y1 = static_cast<int>(std::ceil(cy + r));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const float dx = x + 0.5f - cx, dy = y + 0.5f - cy;
      if (dx * dx + dy * dy <= r * r) set(x, y, c);
    }
}

void Image::disc_z(float cx, float cy, float r, float z, Rgb c) {
  if (depth.empty()) depth.assign(static_cast<std::size_t>(w) * h, std::numeric_limits<float>::infinity());
  const int x0 = static_cast<int>(std::floor(cx - r)), x1 = static_cast<int>(std::ceil(cx + r));
  const int y0 = static_cast<int>(std::floor(cy - r)), y1 = static_cast<int>(std::ceil(cy + r));
  for (int y = std::max(0, y0); y <= std::min(h - 1, y1); ++y)
    for (int x = std::max(0, x0); x <= std::min(w - 1, x1); ++x) {
      const float dx = x + 0.5f - cx, dy = y + 0.5f - cy, q = dx * dx + dy * dy;
      if (q > r * r) continue;
      // A sphere's front surface: nearer at the centre, lit from the upper left.
      const float bulge = std::sqrt(std::max(0.0f, 1 - q / (r * r)));
      const float zz = z - bulge * r;
      float& d = depth[static_cast<std::size_t>(y) * w + x];
      if (zz >= d) continue;
      d = zz;
      const float light = 0.65f + 0.35f * std::clamp(bulge - 0.4f * (dx + dy) / r, 0.0f, 1.0f);
      set(x, y, {static_cast<std::uint8_t>(std::min(255.0f, c.r * light)),
                 static_cast<std::uint8_t>(std::min(255.0f, c.g * light)),
                 static_cast<std::uint8_t>(std::min(255.0f, c.b * light))});
    }
}

void Image::line(float x0, float y0, float x1, float y1, Rgb c) {
  const int n = static_cast<int>(std::max(std::fabs(x1 - x0), std::fabs(y1 - y0))) + 1;
  for (int i = 0; i <= n; ++i) {
    const float t = static_cast<float>(i) / n;
    set(static_cast<int>(std::lround(x0 + t * (x1 - x0))), static_cast<int>(std::lround(y0 + t * (y1 - y0))), c);
  }
}

void Image::text(int x, int y, const std::string& s, Rgb c, int scale) {
  static char buf[60000];
  unsigned char col[4] = {255, 255, 255, 255};
  const int quads = stb_easy_font_print(0, 0, const_cast<char*>(s.c_str()), col, buf, sizeof buf);
  for (int q = 0; q < quads; ++q) {
    const float* v = reinterpret_cast<const float*>(buf + q * 64);  // 4 vertices of 16 bytes
    const float qx0 = v[0], qy0 = v[1], qx1 = v[8], qy1 = v[9];
    rect(x + static_cast<int>(qx0 * scale), y + static_cast<int>(qy0 * scale), x + static_cast<int>(qx1 * scale),
         y + static_cast<int>(qy1 * scale), c);
  }
}

void Image::blit(const Image& src, int x, int y) {
  for (int j = 0; j < src.h; ++j)
    for (int i = 0; i < src.w; ++i) {
      const std::size_t k = 3 * (static_cast<std::size_t>(j) * src.w + i);
      set(x + i, y + j, {src.px[k], src.px[k + 1], src.px[k + 2]});
    }
}

Rgb mix(Rgb a, Rgb b, double t) {
  t = std::clamp(t, 0.0, 1.0);
  auto f = [t](std::uint8_t p, std::uint8_t q) { return static_cast<std::uint8_t>(std::lround(p + t * (q - p))); };
  return {f(a.r, b.r), f(a.g, b.g), f(a.b, b.b)};
}

namespace {
Rgb ramp(const Rgb* stops, int n, double t) {
  t = std::clamp(t, 0.0, 1.0) * (n - 1);
  const int i = std::min(n - 2, static_cast<int>(t));
  return mix(stops[i], stops[i + 1], t - i);
}
}  // namespace

Rgb viridis(double t) {
  static const Rgb s[] = {{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  return ramp(s, 5, t);
}
Rgb ice_map(double t) {
  static const Rgb s[] = {{40, 70, 160}, {120, 170, 225}, {235, 248, 255}};
  return ramp(s, 3, t);
}
Rgb water_map(double t) {
  static const Rgb s[] = {{20, 90, 200}, {120, 60, 170}, {235, 110, 40}};
  return ramp(s, 3, t);
}
Rgb snow_map(double t) {
  static const Rgb s[] = {{70, 85, 110}, {150, 170, 195}, {250, 250, 252}};
  return ramp(s, 3, t);
}

Image filmstrip(const std::vector<Image>& frames, const std::vector<std::string>& captions, const std::string& title) {
  const int gap = 6, top = 34, cap = 16;
  int w = gap, h = 0;
  for (const auto& f : frames) w += f.w + gap, h = std::max(h, f.h);
  Image out(w, h + top + cap + gap, {255, 255, 255});
  out.text(gap, 4, title, {20, 20, 20}, 2);
  int x = gap;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (i < captions.size()) out.text(x + 2, top, captions[i], {40, 40, 40}, 1);
    out.blit(frames[i], x, top + cap);
    x += frames[i].w + gap;
  }
  return out;
}

Image line_chart(int w, int h, const std::vector<double>& x, const std::vector<Series>& series, double y_lo, double y_hi,
                 double hline, const std::string& title, const std::string& x_label) {
  Image img(w, h, {255, 255, 255});
  const int l = 56, r = 150, t = 22, b = 26;
  const double x_lo = x.empty() ? 0 : x.front(), x_hi = x.empty() ? 1 : std::max(x.back(), x.front() + 1e-12);
  auto px = [&](double v) { return static_cast<float>(l + (v - x_lo) / (x_hi - x_lo) * (w - l - r)); };
  auto py = [&](double v) { return static_cast<float>(h - b - (v - y_lo) / (y_hi - y_lo) * (h - t - b)); };
  img.text(l, 4, title, {20, 20, 20}, 1);
  img.line(static_cast<float>(l), static_cast<float>(t), static_cast<float>(l), static_cast<float>(h - b), {0, 0, 0});
  img.line(static_cast<float>(l), static_cast<float>(h - b), static_cast<float>(w - r), static_cast<float>(h - b), {0, 0, 0});
  for (int k = 0; k <= 4; ++k) {
    const double yv = y_lo + k * (y_hi - y_lo) / 4, xv = x_lo + k * (x_hi - x_lo) / 4;
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", yv);
    img.text(4, static_cast<int>(py(yv)) - 4, buf, {60, 60, 60});
    img.line(static_cast<float>(l - 3), py(yv), static_cast<float>(l), py(yv), {0, 0, 0});
    std::snprintf(buf, sizeof buf, "%.3g", xv);
    img.text(static_cast<int>(px(xv)) - 8, h - b + 6, buf, {60, 60, 60});
  }
  img.text(w - r - 40, h - b + 6 + 10, x_label, {60, 60, 60});
  if (std::isfinite(hline))
    for (float xx = static_cast<float>(l); xx < w - r; xx += 8) img.line(xx, py(hline), xx + 4, py(hline), {150, 150, 150});
  int ly = t;
  for (const auto& s : series) {
    for (std::size_t i = 1; i < s.y.size() && i < x.size(); ++i) {
      const double a = s.y[i - 1], c = s.y[i];
      if (!std::isfinite(a) || !std::isfinite(c)) continue;  // no data (e.g. no solid left)
      const float ya = py(std::clamp(a, y_lo, y_hi)), yc = py(std::clamp(c, y_lo, y_hi));
      img.line(px(x[i - 1]), ya, px(x[i]), yc, s.colour);
      img.line(px(x[i - 1]), ya + 1, px(x[i]), yc + 1, s.colour);
    }
    img.rect(w - r + 8, ly + 2, w - r + 20, ly + 6, s.colour);
    img.text(w - r + 24, ly, s.label, {30, 30, 30});
    ly += 14;
  }
  return img;
}

bool write_png(const std::string& path, const Image& img) {
  return stbi_write_png(path.c_str(), img.w, img.h, 3, img.px.data(), img.w * 3) != 0;
}

}  // namespace host
