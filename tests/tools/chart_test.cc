#include "common/chart_file.h"

#include <cairo.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "textile/sim/core/error.h"

namespace fs = std::filesystem;

namespace textile::chart {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

fs::path ScratchDir(const std::string& name) {
  const fs::path d = fs::path(TEXTILE_BINARY_DIR) / "test_scratch" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// The 1, 2 or 5 × 10^e nearest to step.
double NearestNiceStep(double step) {
  const double decade = std::pow(10.0, std::floor(std::log10(step)));
  double best = decade;
  for (double m : {2.0, 5.0, 10.0}) {
    if (std::abs(m * decade - step) < std::abs(best - step)) best = m * decade;
  }
  return best;
}

// True if v is an integer multiple of step (v/step is within rounding of an integer).
bool IsMultipleOf(double v, double step) {
  const double k = v / step;
  return std::abs(k - std::round(k)) < 1e-9 * std::max(1.0, std::abs(k));
}

// A decoded PNG; pixel colours as 0..255 RGB.
class Image {
 public:
  explicit Image(const std::string& path)
      : surface_(cairo_image_surface_create_from_png(path.c_str()), cairo_surface_destroy) {}
  bool ok() const { return cairo_surface_status(surface_.get()) == CAIRO_STATUS_SUCCESS; }
  int width() const { return cairo_image_surface_get_width(surface_.get()); }
  int height() const { return cairo_image_surface_get_height(surface_.get()); }
  std::array<int, 3> At(int x, int y) const {
    const unsigned char* data = cairo_image_surface_get_data(surface_.get());
    const int stride = cairo_image_surface_get_stride(surface_.get());
    uint32_t px;
    std::memcpy(&px, data + y * stride + 4 * x, 4);  // native-endian xRGB
    return {static_cast<int>((px >> 16) & 0xFF), static_cast<int>((px >> 8) & 0xFF),
            static_cast<int>(px & 0xFF)};
  }

  // Pixels within a small distance of c (anti-aliased edges blend with white, so only
  // the cores of lines and markers match).
  struct Match {
    int count = 0, x_min = 1 << 30, x_max = -1, y_min = 1 << 30, y_max = -1;
  };
  Match Find(Rgb c) const {
    Match m;
    for (int y = 0; y < height(); ++y) {
      for (int x = 0; x < width(); ++x) {
        const auto p = At(x, y);
        const double d =
            std::abs(p[0] - 255 * c.r) + std::abs(p[1] - 255 * c.g) + std::abs(p[2] - 255 * c.b);
        if (d > kColorTolerance) continue;
        ++m.count;
        m.x_min = std::min(m.x_min, x), m.x_max = std::max(m.x_max, x);
        m.y_min = std::min(m.y_min, y), m.y_max = std::max(m.y_max, y);
      }
    }
    return m;
  }

 private:
  // Sum of |ΔR|+|ΔG|+|ΔB| over 0..255: well inside the gap between palette colours.
  static constexpr double kColorTolerance = 40;
  std::unique_ptr<cairo_surface_t, void (*)(cairo_surface_t*)> surface_;
};

Series Line(std::vector<double> x, std::vector<double> y, std::string label = "") {
  Series s;
  s.label = std::move(label);
  s.x = std::move(x);
  s.y = std::move(y);
  return s;
}

Figure OnePanel(Panel panel, int width = 600, int height = 400) {
  Figure f;
  f.width_px = width;
  f.height_px = height;
  f.panels = {std::move(panel)};
  return f;
}

TEST(NiceTicks, AreOneTwoFiveMultiplesCoveringTheRange) {
  const std::vector<std::pair<double, double>> ranges = {
      {0, 1},        {0, 10},    {-1, 1},       {-7.3, -2.1},   {0.13, 0.17},   {1e-9, 3e-9},
      {-2e-9, 5e-9}, {0, 1e9},   {-3e9, 7e9},   {1e9, 1.001e9}, {-0.5, 1234.5}, {99.9, 100.1},
      {3, 3.0001},   {-1e-3, 0}, {0.001, 1000}, {17, 23}};
  for (const auto& [lo, hi] : ranges) {
    for (int max_count : {3, 5, 8, 11}) {
      SCOPED_TRACE(std::to_string(lo) + " .. " + std::to_string(hi) + ", max " +
                   std::to_string(max_count));
      const Ticks t = NiceTicks(lo, hi, max_count);
      ASSERT_GE(t.values.size(), 2u);
      ASSERT_LE(t.values.size(), static_cast<size_t>(max_count));
      ASSERT_EQ(t.labels.size(), t.values.size());
      const double step = NearestNiceStep(t.values[1] - t.values[0]);
      // Ticks may sit on an end up to rounding of lo/step (1e-9 of a step).
      const double slack = 1e-6 * step;
      EXPECT_GE(t.values.front(), lo - slack);
      EXPECT_LE(t.values.back(), hi + slack);
      // Covering: no gap of a whole step between an end of the range and the nearest tick.
      EXPECT_LT(t.values.front() - lo, step * (1 + 1e-6));
      EXPECT_LT(hi - t.values.back(), step * (1 + 1e-6));
      for (size_t i = 0; i < t.values.size(); ++i) {
        EXPECT_TRUE(IsMultipleOf(t.values[i], step)) << t.values[i] << " step " << step;
        if (i > 0) {
          // Differences of nearby large values lose digits: 1e-6 of a step is still exact enough.
          EXPECT_NEAR(t.values[i] - t.values[i - 1], step, 1e-6 * step);
        }
      }
    }
  }
}

TEST(NiceTicks, UsesTheFinestStepThatFits) {
  // 0..1 with up to 11 ticks: step 0.1, not 0.2.
  EXPECT_EQ(NiceTicks(0, 1, 11).values.size(), 11u);
  EXPECT_EQ(NiceTicks(0, 1, 10).values.size(), 6u);  // 0, 0.2, ..., 1
  EXPECT_EQ(NiceTicks(0, 1, 5).values.size(), 3u);   // 0, 0.5, 1
}

TEST(NiceTicks, LabelsAreCompact) {
  const Ticks t = NiceTicks(0, 1, 11);
  ASSERT_EQ(t.labels.size(), 11u);
  EXPECT_EQ(t.labels[0], "0");
  EXPECT_EQ(t.labels[3], "0.3");  // not 0.30000000000000004
  EXPECT_EQ(t.labels[10], "1.0");
  EXPECT_EQ(NiceTicks(-2, 2, 5).labels.front(), "\u22122");  // minus sign, not a hyphen
  EXPECT_EQ(NiceTicks(0, 1e9, 6).labels[1], "2×10⁸");
  EXPECT_EQ(NiceTicks(0, 4e-5, 5).labels[1], "1×10⁻⁵");
  EXPECT_EQ(NiceTicks(0, 2.2e9, 4).labels,
            (std::vector<std::string>{"0", "1×10⁹", "2×10⁹"}));  // no "1.0×10⁹"
  EXPECT_EQ(NiceTicks(0.9e9, 1.3e9, 5).labels,
            (std::vector<std::string>{"9×10⁸", "1×10⁹", "1.1×10⁹", "1.2×10⁹", "1.3×10⁹"}));
  for (const auto& label : NiceTicks(1e-9, 3e-9, 6).labels) {
    EXPECT_LE(label.size(), 16u) << label;
    EXPECT_NE(label.find("×10⁻⁹"), std::string::npos) << label;
  }
  for (const auto& label : NiceTicks(0.1, 0.7, 7).labels) EXPECT_EQ(label.size(), 3u) << label;
}

TEST(NiceTicks, EmptyForEmptyOrNonFiniteRange) {
  EXPECT_TRUE(NiceTicks(1, 1, 5).values.empty());
  EXPECT_TRUE(NiceTicks(2, 1, 5).values.empty());
  EXPECT_TRUE(NiceTicks(0, kInf, 5).values.empty());
  EXPECT_TRUE(NiceTicks(kNaN, 1, 5).values.empty());
}

TEST(LogTicks, MarkDecades) {
  const Ticks t = LogTicks(2e-6, 300, 10);
  ASSERT_EQ(t.values.size(), 8u);  // 10⁻⁵ .. 10²
  for (size_t i = 0; i < t.values.size(); ++i) {
    const double e = std::log10(t.values[i]);
    EXPECT_NEAR(e, std::round(e), 1e-12);
  }
  EXPECT_EQ(t.labels.front(), "10⁻⁵");
  EXPECT_EQ(t.labels.back(), "10²");
  EXPECT_FALSE(t.minor.empty());  // 2..9 × 10ⁿ in between
}

TEST(LogTicks, SkipDecadesOverWideRanges) {
  const Ticks t = LogTicks(1e-12, 1e12, 6);
  EXPECT_GE(t.values.size(), 2u);
  EXPECT_LE(t.values.size(), 6u);
  for (double v : t.values) {
    const double e = std::log10(v);
    EXPECT_NEAR(e, std::round(e), 1e-12);
  }
}

TEST(LogTicks, NarrowRangeFallsBackToOneTwoFive) {
  const Ticks t = LogTicks(1.5, 30, 8);
  EXPECT_EQ(t.labels, (std::vector<std::string>{"2", "5", "10", "20"}));
  EXPECT_TRUE(LogTicks(0, 10, 5).values.empty());  // not a log range
}

TEST(Chart, WritesPngOfRequestedSizeWithTheSeriesDrawn) {
  const fs::path d = ScratchDir("chart_basic");
  Panel p;
  p.title = "Moment–curvature";
  p.x_label = "κ [1/cm]";
  p.y_label = "M [gf·cm/cm]";
  std::vector<double> x, y;
  for (int i = 0; i <= 50; ++i) {
    x.push_back(0.05 * i);
    y.push_back(std::tanh(0.05 * i));
  }
  p.series.push_back(Line(x, y, "fit"));
  p.notes = {"B₀ = 0.12 gf·cm²/cm"};
  const std::string path = (d / "mk.png").string();
  WritePng(OnePanel(p, 640, 480), path);

  const Image img(path);
  ASSERT_TRUE(img.ok());
  EXPECT_EQ(img.width(), 640);
  EXPECT_EQ(img.height(), 480);
  const auto blue = img.Find(PaletteColor(0));
  // A 2 px curve across most of a ~500 px wide plot covers far more than 300 pixels.
  EXPECT_GT(blue.count, 300);
  EXPECT_GT(blue.x_max - blue.x_min, 300);
  EXPECT_EQ(img.Find(PaletteColor(1)).count, 0);  // no second series, no second colour
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator{}), 1);
}

TEST(Chart, SkipsNaNPointsAndEmptySeries) {
  const fs::path d = ScratchDir("chart_nan");
  Panel p;
  p.series.push_back(Line({0, 1, 2, 3, 4, 5}, {0, 1, kNaN, 3, kInf, 5}, "gappy"));
  p.series.push_back(Line({kNaN, kNaN}, {1, 2}, "all NaN"));
  const std::string path = (d / "nan.png").string();
  ASSERT_NO_THROW(WritePng(OnePanel(p), path));
  const Image img(path);
  ASSERT_TRUE(img.ok());
  EXPECT_GT(img.Find(PaletteColor(0)).count, 30);
  // Neither drawn nor in the legend.
  EXPECT_EQ(img.Find(PaletteColor(1)).count, 0);
}

TEST(Chart, PanelWithoutDataStillRenders) {
  const fs::path d = ScratchDir("chart_empty");
  Panel empty;
  empty.title = "nothing";
  empty.series.push_back(Line({kNaN}, {kNaN}, "x"));
  Panel none;  // no series at all
  none.log_x = true;
  Figure f = OnePanel(empty);
  f.panels.push_back(none);
  f.columns = 2;
  const std::string path = (d / "empty.png").string();
  ASSERT_NO_THROW(WritePng(f, path));
  EXPECT_TRUE(Image(path).ok());
}

TEST(Chart, LogAxesSkipNonPositivePoints) {
  const fs::path d = ScratchDir("chart_log");
  Panel p;
  p.log_x = p.log_y = true;
  p.series.push_back(Line({1, 2, 3}, {0, -1, -5}, "never positive"));
  p.series.push_back(Line({-1, 0, 1e-3, 1e-2, 1e-1, 1}, {5, 5, 1, 1e-2, 1e-4, 1e-6}, "error"));
  const std::string path = (d / "log.png").string();
  WritePng(OnePanel(p), path);
  const Image img(path);
  ASSERT_TRUE(img.ok());
  EXPECT_EQ(img.Find(PaletteColor(0)).count, 0);
  EXPECT_GT(img.Find(PaletteColor(1)).count, 200);
}

TEST(Chart, EqualAspectDrawsASquareAsASquare) {
  const fs::path d = ScratchDir("chart_aspect");
  Panel p;
  p.x_label = "x [mm]";
  p.y_label = "z [mm]";
  p.series.push_back(Line({0, 40, 40, 0, 0}, {0, 0, 10, 10, 0}));  // a 40×10 mm rectangle
  p.series[0].line_width = 3;  // thick enough for pixels of the exact colour
  for (bool equal : {false, true}) {
    p.equal_aspect = equal;
    const std::string path = (d / (equal ? "equal.png" : "free.png")).string();
    WritePng(OnePanel(p, 500, 700), path);  // tall image: free axes would stretch z
    const auto box = Image(path).Find(PaletteColor(0));
    ASSERT_GT(box.count, 0);
    const double w = box.x_max - box.x_min, h = box.y_max - box.y_min;
    if (equal) {
      // Same scale on both axes: the height is a quarter of the width to within 3 px
      // (the line's width and anti-aliasing at the corners).
      EXPECT_NEAR(w, 4 * h, 4 * 3.0) << w << " × " << h;
    } else {
      EXPECT_LT(w / h, 2.0) << "the test would not notice a stretched plot";
    }
  }
}

TEST(Chart, UnwritablePathThrowsAndLeavesNothing) {
  Panel p;
  p.series.push_back(Line({0, 1}, {0, 1}));
  const std::string path = "/nonexistent-textile-chart-dir/x.png";
  try {
    WritePng(OnePanel(p), path);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path));
}

TEST(Chart, BadFigureThrowsInputErrorNamingTheProblem) {
  const fs::path d = ScratchDir("chart_bad");
  Panel p;
  p.title = "profile";
  p.series.push_back(Line({0, 1, 2}, {0, 1}, "measured"));
  const std::string path = (d / "bad.png").string();
  try {
    WritePng(OnePanel(p), path);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("x and y differ in length"), std::string::npos) << what;
    EXPECT_NE(what.find("measured"), std::string::npos) << what;
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_THROW(WritePng(OnePanel(Panel{}), (d / "chart.jpg").string()), InputError);
  Panel log_range;
  log_range.log_y = true;
  log_range.y_range = Range{0, 10};
  std::string why;
  EXPECT_FALSE(OnePanel(log_range).Check(&why));
  EXPECT_NE(why.find("positive"), std::string::npos) << why;
}

TEST(Chart, DrawsIntoAStagedFileThatAppearsOnlyWithItsSet) {
  const fs::path d = ScratchDir("chart_staged");
  Panel p;
  p.series.push_back(Line({0, 1, 2}, {0, 1, 4}, "fit"));
  const std::string path = (d / "fit.png").string();
  {
    // Drawn, but the set is dropped (a later output failed): nothing appears, no temp is left.
    AtomicFileSet outputs;
    WritePng(OnePanel(p), outputs.Add(path));
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_EQ(std::distance(fs::directory_iterator(d), fs::directory_iterator{}), 0);
  AtomicFileSet outputs;
  AtomicFile& staged = outputs.Add(path);
  WritePng(OnePanel(p), staged);
  EXPECT_FALSE(fs::exists(path));  // not before the set's Commit
  outputs.Commit();
  const Image img(path);
  ASSERT_TRUE(img.ok());
  EXPECT_GT(img.Find(PaletteColor(0)).count, 30);
  // The name is checked as WritePng(figure, path) checks it, before anything is drawn.
  AtomicFileSet other;
  EXPECT_THROW(WritePng(OnePanel(p), other.Add((d / "fit.jpg").string())), InputError);
  EXPECT_THROW(CheckPngPath((d / "fit.svg").string()), InputError);
  EXPECT_NO_THROW(CheckPngPath((d / "FIT.PNG").string()));
}

TEST(Chart, InvalidUtf8LabelStillDrawsTheChart) {
  const fs::path d = ScratchDir("chart_utf8");
  Panel p;
  p.title = "bad \xff\xfe name";
  p.series.push_back(Line({0, 1}, {0, 1}, "s\xc3"));
  const std::string path = (d / "utf8.png").string();
  WritePng(OnePanel(p), path);
  EXPECT_GT(Image(path).Find(PaletteColor(0)).count, 100);
}

}  // namespace
}  // namespace textile::chart
