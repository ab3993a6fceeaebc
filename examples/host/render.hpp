// Frames: particles splatted as discs into an RGB image (2D: the grid's square seen from the
// front; 3D: an orthographic view from above-front, z-buffered, darker with depth), colour
// maps, text (stb_easy_font), a line chart, filmstrips, and PNG output (stb_image_write).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace host {

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
};

struct Image {
  int w = 0, h = 0;
  std::vector<std::uint8_t> px;  // RGB, row 0 at the top
  std::vector<float> depth;      // z-buffer (3D splats)
  Image() = default;
  Image(int width, int height, Rgb bg);
  void set(int x, int y, Rgb c);
  void rect(int x0, int y0, int x1, int y1, Rgb c);  // [x0, x1) × [y0, y1)
  void disc(float cx, float cy, float r, Rgb c);
  void disc_z(float cx, float cy, float r, float z, Rgb c);  // drawn where nearer (smaller z)
  void line(float x0, float y0, float x1, float y1, Rgb c);
  void text(int x, int y, const std::string& s, Rgb c, int scale = 1);
  void blit(const Image& src, int x, int y);
};

/// Colour maps on t in [0, 1] (clamped).
Rgb viridis(double t);
Rgb ice_map(double t);    // deep blue → white (cold solid)
Rgb water_map(double t);  // blue → orange (liquid warming)
Rgb snow_map(double t);   // compressed (slate) → fresh (white)
Rgb mix(Rgb a, Rgb b, double t);

/// Frames side by side with a gap, each with its caption above.
Image filmstrip(const std::vector<Image>& frames, const std::vector<std::string>& captions, const std::string& title);

/// A line chart of series over x (each series: y values, colour, label); `hline` draws a
/// dashed reference line (e.g. T_m) when finite.
struct Series {
  std::vector<double> y;
  Rgb colour;
  std::string label;
};
Image line_chart(int w, int h, const std::vector<double>& x, const std::vector<Series>& series, double y_lo, double y_hi,
                 double hline, const std::string& title, const std::string& x_label);

/// Writes an RGB PNG with stb_image_write; false on failure.
bool write_png(const std::string& path, const Image& img);

}  // namespace host
