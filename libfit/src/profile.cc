#include "textile/fit/profile.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <sstream>

#include "csv_text.h"
#include "textile/sim/core/error.h"

namespace textile {
namespace {

// How far above the platform's top a mid-line point may lie: half a thickness of the thickest
// fabrics plus extraction noise. Beyond that the strip "rises above the platform".
constexpr double kMaxRiseM = 3e-3;
// How far x may run backwards before we call it folding back (noise on a vertical tail).
constexpr double kFoldBackM = 1e-3;
// A rig tilted by up to this much [rad] (3°; `fit --fit-rotation` fits it) turns a vertical
// tail back by sin(tilt) per unit of arc length: a 2° tilt once refused synth-profile's own
// 80 mm profile as folding back.
constexpr double kMaxTiltRad = 3.0 * std::numbers::pi / 180.0;

using internal::SplitComma;
using internal::Trim;

}  // namespace

Profile ParseProfileCsv(const std::string& text, const std::string& source) {
  Profile p;
  p.source = source;
  std::stringstream in(text);
  std::string line;
  int line_no = 0;
  bool header_seen = false;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = Trim(line);
    if (t.empty() || t[0] == '#') continue;
    const auto where = [&] { return source + ":" + std::to_string(line_no) + ": "; };
    if (!header_seen) {
      std::string h;
      for (char c : t)
        if (c != ' ' && c != '\t') h += c;
      if (h.rfind("\xEF\xBB\xBF", 0) == 0) h = h.substr(3);  // UTF-8 byte-order mark
      if (h != "s_mm,x_mm,y_mm") {
        throw InputError(where() + "expected the header 's_mm,x_mm,y_mm', got '" + t.substr(0, 60) +
                         "'");
      }
      header_seen = true;
      continue;
    }
    const auto cells = SplitComma(t);
    if (cells.size() != 3) {
      throw InputError(where() + "expected 3 values (s_mm,x_mm,y_mm), got " +
                       std::to_string(cells.size()));
    }
    double v[3];
    for (int k = 0; k < 3; ++k) {
      const char* c = cells[k].c_str();
      char* end = nullptr;
      v[k] = std::strtod(c, &end);
      if (cells[k].empty() || end == c || *end != '\0') {
        throw InputError(where() + "'" + cells[k].substr(0, 30) + "' is not a number");
      }
      if (!std::isfinite(v[k])) throw InputError(where() + "value is NaN or infinite");
      if (std::abs(v[k]) > 1e5) {
        throw InputError(where() + "|" + cells[k] + "| mm is implausibly large for a cantilever");
      }
    }
    p.s.push_back(v[0] * 1e-3);
    p.x.push_back(v[1] * 1e-3);
    p.y.push_back(v[2] * 1e-3);
  }
  if (!header_seen) throw InputError(source + ": empty profile (no header 's_mm,x_mm,y_mm')");
  CheckProfile(p);
  return p;
}

Profile ReadProfileCsv(const std::string& path) {
  // 64 MB: two million points, a thousand times an extracted profile.
  return ParseProfileCsv(ReadInputFile(path, "profile", 64u << 20), path);
}

void CheckProfile(const Profile& p) {
  const std::string& src = p.source;
  if (p.x.size() != p.s.size() || p.y.size() != p.s.size()) {
    throw InputError(src + ": s, x and y differ in length");
  }
  if (p.size() < static_cast<size_t>(kMinProfilePoints)) {
    throw InputError(src + ": " + std::to_string(p.size()) + " points, at least " +
                     std::to_string(kMinProfilePoints) + " are needed");
  }
  // Folding back means x running backwards by more than noise can explain: the threshold is
  // kFoldBackM or 8σ of the point noise, whichever is larger, σ estimated robustly from second
  // differences (1.4826 × median |Δ²x| / √6 for white noise).
  std::vector<double> d2;
  for (size_t i = 1; i + 1 < p.size(); ++i) {
    const double v = std::abs(p.x[i + 1] - 2 * p.x[i] + p.x[i - 1]);
    if (std::isfinite(v)) d2.push_back(v);  // non-finite points are refused below
  }
  double fold_back = kFoldBackM;
  if (!d2.empty()) {
    std::nth_element(d2.begin(), d2.begin() + d2.size() / 2, d2.end());
    const double sigma = 1.4826 * d2[d2.size() / 2] / std::sqrt(6.0);
    if (std::isfinite(sigma)) fold_back = std::max(fold_back, 8.0 * sigma);
  }
  double max_x = -1e300;
  for (size_t i = 0; i < p.size(); ++i) {
    const std::string row = "point " + std::to_string(i + 1);
    if (!std::isfinite(p.s[i]) || !std::isfinite(p.x[i]) || !std::isfinite(p.y[i])) {
      throw InputError(src + ": " + row + " is NaN or infinite");
    }
    if (i > 0 && !(p.s[i] > p.s[i - 1])) {
      throw InputError(src + ": " + row + ": arc length s_mm must increase strictly (" +
                       std::to_string(p.s[i - 1] * 1e3) + " then " + std::to_string(p.s[i] * 1e3) +
                       ")");
    }
    if (p.y[i] > kMaxRiseM) {
      // A mid-line starts half a thickness up: near the edge, a thick strip is the likelier cause.
      const std::string cause =
          std::hypot(p.x[i] - p.x.front(), p.y[i] - p.y.front()) < 2 * kMaxRiseM
              ? "; a strip thicker than " + std::to_string(static_cast<int>(2e3 * kMaxRiseM)) +
                    " mm, whose mid-line starts higher, is not supported"
              : "";
      throw InputError(src + ": " + row + " lies " + std::to_string(p.y[i] * 1e3) +
                       " mm above the platform, more than " +
                       std::to_string(static_cast<int>(1e3 * kMaxRiseM)) +
                       " mm; a hanging strip has y_mm <= 0 (is y pointing down?)" + cause);
    }
    // The tilt's allowance grows with the distance from the first point, not with s, which noise
    // inflates (a 60 mm strip's dense noisy points measured s = 545 mm).
    const double from_start = std::hypot(p.x[i] - p.x.front(), p.y[i] - p.y.front());
    if (p.x[i] < max_x - std::max(fold_back, std::sin(kMaxTiltRad) * from_start)) {
      if (max_x <= fold_back)  // never went right: an overhang to the left
        throw InputError(
            src + ": " + row + ": x_mm runs backwards from the edge (to " +
            std::to_string(p.x[i] * 1e3) +
            "); x must point along the overhang (mirror a left overhang: x_mm -> -x_mm)");
      throw InputError(src + ": " + row + ": the profile folds back (x_mm decreases from " +
                       std::to_string(max_x * 1e3) + " to " + std::to_string(p.x[i] * 1e3) + ")");
    }
    max_x = std::max(max_x, p.x[i]);
  }
  if (p.s.front() < -kFoldBackM) {
    throw InputError(src + ": arc length starts at " + std::to_string(p.s.front() * 1e3) +
                     " mm; s_mm is measured from the platform edge and must be >= 0");
  }
}

std::string ProfileToCsv(const Profile& p) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(6);
  out << "s_mm,x_mm,y_mm\n";
  for (size_t i = 0; i < p.size(); ++i) {
    out << p.s[i] * 1e3 << ',' << p.x[i] * 1e3 << ',' << p.y[i] * 1e3 << '\n';
  }
  return out.str();
}

double ProfilePointScatter(const Profile& p) {
  std::vector<double> d;
  for (size_t i = 1; i + 1 < p.size(); ++i) {
    const double tx = p.x[i + 1] - p.x[i - 1], ty = p.y[i + 1] - p.y[i - 1];
    const double t = std::hypot(tx, ty);
    if (!(t > 0.0)) continue;
    const double mx = 0.5 * (p.x[i + 1] + p.x[i - 1]), my = 0.5 * (p.y[i + 1] + p.y[i - 1]);
    d.push_back(std::abs((p.x[i] - mx) * ty - (p.y[i] - my) * tx) / t);
  }
  if (d.empty()) return 0.0;
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return 1.4826 * d[d.size() / 2] / std::sqrt(1.5);
}

}  // namespace textile
