// Blocks (clamps, platforms) on the reduced image, and the platform's top face, front face and
// corner at full resolution.

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <optional>
#include <opencv2/imgproc.hpp>

#include "extract_internal.h"

namespace textile::extract_internal {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Robust straight line v = a + b·u through (u, v) points: least squares, then points farther
// than max(1 px, 3σ) are dropped and the line refitted, a few times. Returns the RMS of the
// kept points; *kept counts them.
double FitLineRobust(const std::vector<Vec2>& uv, double* a, double* b, int* kept) {
  std::vector<char> use(uv.size(), 1);
  double rms = 1e9;
  for (int iter = 0; iter < 5; ++iter) {
    Eigen::Matrix2d n = Eigen::Matrix2d::Zero();
    Eigen::Vector2d r = Eigen::Vector2d::Zero();
    int count = 0;
    for (size_t i = 0; i < uv.size(); ++i) {
      if (!use[i]) continue;
      const Eigen::Vector2d row(1.0, uv[i].x());
      n += row * row.transpose();
      r += row * uv[i].y();
      ++count;
    }
    if (count < 2 || std::abs(n.determinant()) < 1e-9) return 1e9;
    const Eigen::Vector2d ab = n.ldlt().solve(r);
    *a = ab(0);
    *b = ab(1);
    std::vector<double> res;
    for (size_t i = 0; i < uv.size(); ++i) res.push_back(std::abs(uv[i].y() - *a - *b * uv[i].x()));
    std::vector<double> used;
    for (size_t i = 0; i < uv.size(); ++i)
      if (use[i]) used.push_back(res[i]);
    const double sigma = 1.4826 * Median(used);
    const double cut = std::max(1.0, 3.0 * sigma);
    double s2 = 0.0;
    *kept = 0;
    for (size_t i = 0; i < uv.size(); ++i) {
      use[i] = res[i] <= cut;
      if (use[i]) {
        s2 += res[i] * res[i];
        ++*kept;
      }
    }
    rms = *kept > 0 ? std::sqrt(s2 / *kept) : 1e9;
  }
  return rms;
}

// Position of the first clear intensity step along a line of samples, searching from the
// start (inside the block) outwards: the first local maximum of |derivative| that reaches 30 %
// of the largest one on the line and is not noise, refined by a parabola. -1 if there is none.
// Units: samples. Not noise: the grey level changes across it by 30 % of the largest such
// change on the line, or its derivative stands 6 σ above the noise's. On a long line (a thick
// strip at 50 MP searches 50 px into the block) the noise alone has derivative peaks of 30 % of
// a 30-grey-level face's, but the mean grey 1.5-4 px either side of such a peak hardly differs;
// the edge between a platform and a strip 3-5 px thick lying on it changes the mean less than
// that (the strip is narrower than the window) but is far above the noise.
double FirstStep(const std::vector<double>& v) {
  const int n = static_cast<int>(v.size());
  if (n < 5) return -1.0;
  std::vector<double> d(n, 0.0);
  for (int i = 1; i + 1 < n; ++i) d[i] = std::abs(v[i + 1] - v[i - 1]) / 2.0;
  const double top = *std::max_element(d.begin(), d.end());
  if (top <= 0.0) return -1.0;
  // The derivative's noise: a few samples are edges, the median is the noise's.
  const double noise = 1.4826 * Median(std::vector<double>(d.begin() + 1, d.end() - 1));
  // |mean of samples i+3..i+8 - mean of samples i-8..i-3| (1.5-4 px: past the blur of a face),
  // clipped to the line.
  const auto change = [&](int i) {
    double before = 0.0, after = 0.0;
    int nb = 0, na = 0;
    for (int k = 3; k <= 8; ++k) {
      if (i - k >= 0) {
        before += v[i - k];
        ++nb;
      }
      if (i + k < n) {
        after += v[i + k];
        ++na;
      }
    }
    return nb > 0 && na > 0 ? std::abs(after / na - before / nb) : 0.0;
  };
  std::vector<int> peaks;
  double top_change = 0.0;
  for (int i = 2; i + 2 < n; ++i) {
    if (d[i] >= 0.3 * top && d[i] >= d[i - 1] && d[i] > d[i + 1]) {
      peaks.push_back(i);
      top_change = std::max(top_change, change(i));
    }
  }
  for (int i : peaks) {
    if (change(i) < 0.3 * top_change && d[i] < 6.0 * noise) continue;
    const double den = d[i - 1] - 2.0 * d[i] + d[i + 1];
    const double delta = den < 0.0 ? 0.5 * (d[i - 1] - d[i + 1]) / den : 0.0;
    return i + std::clamp(delta, -0.5, 0.5);
  }
  return -1.0;
}

// Samples of the grey image from `from` towards `to`, every 0.5 px, smoothed with σ = 1 px
// along the line and averaged over `across` px either side of it (along the face being
// scanned for: faint faces under heavy noise need the average).
std::vector<double> LineSamples(const cv::Mat& gray, const Vec2& from, const Vec2& to,
                                int across) {
  const double len = (to - from).norm();
  const int n = static_cast<int>(len / 0.5) + 1;
  const Vec2 along = (to - from) / std::max(len, 1e-9);
  const Vec2 side(-along.y(), along.x());
  std::vector<double> raw;
  for (int i = 0; i < n; ++i) {
    const Vec2 p = from + along * (i * 0.5);
    double sum = 0.0, v;
    bool inside = true;
    for (int k = -across; k <= across && inside; ++k) {
      const Vec2 q = p + k * side;
      inside = SampleGray(gray, q.x(), q.y(), &v);
      sum += v;
    }
    if (!inside) break;
    raw.push_back(sum / (2 * across + 1));
  }
  std::vector<Vec2> as_points;
  for (double v : raw) as_points.emplace_back(v, 0.0);
  const auto smooth = SmoothPolyline(as_points, 2.0);
  std::vector<double> out;
  for (const auto& p : smooth) out.push_back(p.x());
  return out;
}

}  // namespace

std::vector<Block> FindBlocks(const cv::Mat& small, const cv::Mat& ignore, double min_thickness) {
  const int w = small.cols, h = small.rows;
  // Background model: quadratic in normalised coordinates, fitted on a grid of about 20k
  // samples with outliers (the strip, blocks) trimmed at 2.5σ.
  const int g = std::max(1, static_cast<int>(std::lround(std::sqrt(w * h / 20000.0))));
  const auto u_of = [&](double x) { return (x - w / 2.0) / (w / 2.0); };
  const auto v_of = [&](double y) { return (y - h / 2.0) / (h / 2.0); };
  std::vector<Eigen::Matrix<double, 1, 6>> grid;
  std::vector<double> samples;
  for (int y = g / 2; y < h; y += g) {
    for (int x = g / 2; x < w; x += g) {
      if (ignore.at<uchar>(y, x)) continue;
      const double u = u_of(x), v = v_of(y);
      grid.push_back((Eigen::Matrix<double, 1, 6>() << 1.0, u, v, u * u, u * v, v * v).finished());
      samples.push_back(small.at<uchar>(y, x));
    }
  }
  if (grid.size() < 50) return {};
  const Eigen::Index count = static_cast<Eigen::Index>(grid.size());
  Eigen::Matrix<double, Eigen::Dynamic, 6> rows(count, 6);
  for (Eigen::Index i = 0; i < count; ++i) rows.row(i) = grid[i];
  const Eigen::Map<const Eigen::VectorXd> values(samples.data(), count);
  // Trimmed least squares from a starting set of inliers: fit, then keep samples within 2.5σ.
  // The normal equations summed over the inliers (0/1 weights) as one matrix-vector product:
  // column i of `moments` holds sample i's 21 distinct basis products (the upper triangle of
  // rowᵀ row) and its 6 basis values times its grey, formed once.
  constexpr int kProducts = 21, kMoments = kProducts + 6;
  Eigen::Matrix<double, kMoments, Eigen::Dynamic> moments(kMoments, count);
  for (Eigen::Index i = 0; i < count; ++i) {
    int k = 0;
    for (int a = 0; a < 6; ++a)
      for (int b = a; b < 6; ++b) moments(k++, i) = rows(i, a) * rows(i, b);
    for (int a = 0; a < 6; ++a) moments(kProducts + a, i) = rows(i, a) * values(i);
  }
  const auto robust_fit = [&](Eigen::VectorXd inlier, Eigen::Matrix<double, 6, 1>* coef) {
    double sigma = 0.5;
    std::vector<double> abs_in;
    for (int iter = 0; iter < 8; ++iter) {
      const Eigen::Matrix<double, kMoments, 1> sum = moments * inlier;
      Eigen::Matrix<double, 6, 6> n;
      for (int a = 0, k = 0; a < 6; ++a)
        for (int b = a; b < 6; ++b, ++k) n(a, b) = n(b, a) = sum(k);
      const Eigen::Matrix<double, 6, 1> r = sum.tail<6>();
      *coef = n.ldlt().solve(r);
      const Eigen::VectorXd res = (values - rows * *coef).cwiseAbs();
      abs_in.clear();
      for (Eigen::Index i = 0; i < count; ++i)
        if (inlier(i) > 0.0) abs_in.push_back(res(i));
      sigma = std::max(0.5, 1.4826 * Median(abs_in));
      inlier = (res.array() <= 2.5 * sigma).cast<double>();
    }
    return sigma;
  };
  // Two starts: every sample, and the samples near the most common grey (smoothed histogram).
  // The first settles between background and a platform that covers a third of the photo or
  // more, and its trimming then keeps both; the second can stay on a patch of a background whose
  // light falls off strongly. The fit that explains more samples within a tight band wins.
  std::vector<double> hist(256, 0.0);
  for (double v : samples) {
    for (int k = -4; k <= 4; ++k) {
      const int b = static_cast<int>(v) + k;
      if (b >= 0 && b < 256) hist[b] += 1.0;
    }
  }
  const double mode =
      static_cast<double>(std::max_element(hist.begin(), hist.end()) - hist.begin());
  const Eigen::VectorXd near_mode = ((values.array() - mode).abs() <= 20.0).cast<double>();
  const double count_near = near_mode.sum();
  Eigen::Matrix<double, 6, 1> coef, coef_mode;
  double sigma = robust_fit(Eigen::VectorXd::Ones(count), &coef);
  if (count_near >= 50) {
    const double sigma_mode = robust_fit(near_mode, &coef_mode);
    const double band = std::max(3.0 * std::min(sigma, sigma_mode), 3.0);
    const Eigen::Index explained = ((values - rows * coef).array().abs() <= band).count();
    const Eigen::Index explained_mode = ((values - rows * coef_mode).array().abs() <= band).count();
    if (explained_mode > explained) {
      coef = coef_mode;
      sigma = sigma_mode;
    }
  }
  const double thr = std::max(5.0 * sigma, 3.0);
  cv::Mat pos(small.size(), CV_8U, cv::Scalar(0)), neg(small.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < h; ++y) {
    // The model along a row: a + b·u + c·u².
    const double v = v_of(y);
    const double a = coef(0) + coef(2) * v + coef(5) * v * v, b = coef(1) + coef(4) * v,
                 c = coef(3);
    const uchar* in = small.ptr<uchar>(y);
    const uchar* skip = ignore.ptr<uchar>(y);
    uchar* p = pos.ptr<uchar>(y);
    uchar* q = neg.ptr<uchar>(y);
    for (int x = 0; x < w; ++x) {
      if (skip[x]) continue;
      const double u = u_of(x);
      const double r = in[x] - (a + (b + c * u) * u);
      if (r > thr) p[x] = 255;
      if (r < -thr) q[x] = 255;
    }
  }
  const int d = std::max(3, 2 * static_cast<int>(std::ceil(min_thickness)) + 1);
  const cv::Mat disk = cv::getStructuringElement(cv::MORPH_ELLIPSE, {d, d});
  std::vector<Block> blocks;
  for (int sign : {+1, -1}) {
    cv::Mat m = sign > 0 ? pos : neg;
    cv::morphologyEx(m, m, cv::MORPH_OPEN, disk);
    cv::Mat labels, stats;
    const int count = extract_internal::ConnectedComponents(m, &labels, &stats);
    for (int l = 1; l < count; ++l) {
      if (stats.at<int>(l, cv::CC_STAT_AREA) < 0.01 * w * h) continue;
      // Fixtures reach into the photo from outside; a region wholly inside it is part of the
      // scene (an oblique face of the strip, a shadow), not a clamp or a platform.
      const int x0 = stats.at<int>(l, cv::CC_STAT_LEFT), y0 = stats.at<int>(l, cv::CC_STAT_TOP);
      if (x0 > 0 && y0 > 0 && x0 + stats.at<int>(l, cv::CC_STAT_WIDTH) < w &&
          y0 + stats.at<int>(l, cv::CC_STAT_HEIGHT) < h) {
        continue;
      }
      Block b;
      b.mask = labels == l;
      b.sign = sign;
      b.box = cv::Rect(stats.at<int>(l, cv::CC_STAT_LEFT), stats.at<int>(l, cv::CC_STAT_TOP),
                       stats.at<int>(l, cv::CC_STAT_WIDTH), stats.at<int>(l, cv::CC_STAT_HEIGHT));
      blocks.push_back(std::move(b));
    }
  }
  return blocks;
}

std::optional<Block> FindBlockByFrontEdge(const cv::Mat& small, const cv::Mat& ignore,
                                          const std::vector<Vec2>& path, double scale,
                                          int direction, double min_thickness) {
  const int w = small.cols, h = small.rows;
  // The strip's line on the reduced image, a point per reduced pixel.
  std::vector<Vec2> line;
  for (const Vec2& p : path) {
    const Vec2 q = (p + Vec2(0.5, 0.5)) * scale - Vec2(0.5, 0.5);
    if (line.empty() || (q - line.back()).norm() >= 1.0) line.push_back(q);
  }
  if (line.size() < 20) return std::nullopt;
  // Candidate corners: points of the held, near-level part of the line (the strip on the top
  // face), up to where it turns down by 60° (it hangs). If the line comes in from the image
  // border, its first 5 % are left out: a corner there leaves no top face to measure.
  std::vector<int> tops;
  const int reach = 3;
  const bool from_border = line.front().x() < 2.0 || line.front().x() > w - 3.0;
  for (int i = reach; i + reach < static_cast<int>(line.size()); ++i) {
    const Vec2 d = line[i + reach] - line[i - reach];
    const double angle = std::atan2(std::abs(d.y()), std::abs(d.x()));
    if (angle > 60 * kDeg) break;
    if (angle < 30 * kDeg && (!from_border || i >= static_cast<int>(0.05 * line.size())))
      tops.push_back(i);
  }
  if (tops.empty()) return std::nullopt;

  // Horizontal derivative of the lightly smoothed image [grey levels per px], and its noise.
  cv::Mat smooth, gx;
  cv::GaussianBlur(small, smooth, cv::Size(0, 0), 1.0);
  cv::Sobel(smooth, gx, CV_32F, 1, 0, 3, 1.0 / 8.0);
  std::vector<double> abs_g;
  for (int y = 2; y < h - 2; y += 3) {
    for (int x = 2; x < w - 2; x += 3) {
      if (!ignore.at<uchar>(y, x)) abs_g.push_back(std::abs(gx.at<float>(y, x)));
    }
  }
  if (abs_g.size() < 100) return std::nullopt;
  const double noise = std::max(0.02, 1.4826 * Median(abs_g));

  // A front face is a straight edge of one sign from just below the strip to the bottom of
  // the photo (the block stands on the floor of the scene), within ±12° of the vertical. Each
  // candidate line is scored by the mean of the derivative along it in units of the noise, at
  // rows clear of the strip; a line counts when it is long and most of its rows agree in sign.
  const double gap = std::max(3.0, 2.0 * min_thickness);
  struct Line {
    double score = 0.0, x0 = 0.0, y0 = 0.0, slope = 0.0;
    int rows = 0;
  };
  const auto score_line = [&](double x0, double y0, double slope) {
    Line l{0.0, x0, y0, slope, 0};
    double sum = 0.0;
    int agree = 0;
    std::vector<float> values;
    for (int y = static_cast<int>(std::ceil(y0 + gap)); y < h - 1; ++y) {
      const int x = static_cast<int>(std::lround(x0 + slope * (y - y0)));
      if (x < 1 || x >= w - 1) break;
      if (ignore.at<uchar>(y, x)) continue;
      // The sum of three neighbours: the edge is a pixel or two wide on the reduced image and
      // the line is drawn on whole pixels.
      const float* row = gx.ptr<float>(y);
      values.push_back(row[x - 1] + row[x] + row[x + 1]);
      sum += values.back();
    }
    l.rows = static_cast<int>(values.size());
    if (l.rows == 0) return l;
    const double sign = sum >= 0.0 ? 1.0 : -1.0;
    for (float v : values) agree += sign * v > 0.0;
    // Three neighbours: the noise of the sum is about √3 σ (neighbours correlate through the
    // smoothing, so a little more; the threshold below allows for it).
    l.score = agree >= 0.8 * l.rows ? std::abs(sum) / l.rows / (std::sqrt(3.0) * noise) : 0.0;
    return l;
  };
  const int min_rows = std::max(30, h / 5);
  Line best;
  for (int i : tops) {
    const double x0 = line[i].x(), y0 = line[i].y() + 0.5 * min_thickness;
    for (int k = -12; k <= 12; ++k) {
      const Line l = score_line(x0, y0, std::tan(k * kDeg));
      if (l.rows >= min_rows && l.score > best.score) best = l;
    }
  }
  // Refine the tilt around the best line.
  for (int k = -4; k <= 4; ++k) {
    const double slope = std::tan(std::atan(best.slope) + 0.25 * k * kDeg);
    const Line l = score_line(best.x0, best.y0, slope);
    if (l.rows >= min_rows && l.score > best.score) best = l;
  }
  // A step of c grey levels blurred over a few pixels gives a derivative of about c / 3 at its
  // centre: a score of 4 is an edge of a few noise levels' contrast along hundreds of rows,
  // which noise, the background's gradient or the strip's shadow do not make.
  if (best.score < 4.0) return std::nullopt;

  // The block: behind the line (away from the overhang), below the strip.
  Block b;
  b.mask = cv::Mat::zeros(small.size(), CV_8U);
  const double front_y0 = best.y0;
  // The line's lowest point over each column (-1: the line does not cross it).
  std::vector<double> strip_y(w, -1.0);
  for (const Vec2& p : line) {
    const long x = std::lround(p.x());
    if (x >= 0 && x < w && std::abs(p.x() - x) <= 0.5) strip_y[x] = std::max(strip_y[x], p.y());
  }
  for (int x = 0; x < w; ++x) {
    const double y_strip = strip_y[x];
    const double y_top = y_strip >= 0.0 ? y_strip + 0.5 * min_thickness + 0.5 : front_y0;
    for (int y = std::max(0, static_cast<int>(std::ceil(y_top))); y < h; ++y) {
      const double xf = best.x0 + best.slope * (y - best.y0);
      if ((x - xf) * direction <= 0.0 && y >= front_y0) b.mask.at<uchar>(y, x) = 255;
    }
  }
  const cv::Rect box = cv::boundingRect(b.mask);
  if (box.area() < 0.01 * w * h) return std::nullopt;
  b.box = box;
  // Lighter or darker than the background just in front of the face (the sign of the step).
  {
    double inside = 0.0, outside = 0.0;
    int n = 0;
    for (int y = static_cast<int>(front_y0 + gap); y < h; y += 4) {
      const double xf = best.x0 + best.slope * (y - best.y0);
      const int xi = static_cast<int>(std::lround(xf - direction * 4.0));
      const int xo = static_cast<int>(std::lround(xf + direction * 4.0));
      if (xi < 0 || xi >= w || xo < 0 || xo >= w) continue;
      inside += smooth.at<uchar>(y, xi);
      outside += smooth.at<uchar>(y, xo);
      ++n;
    }
    b.sign = n > 0 && inside > outside ? +1 : -1;
  }
  return b;
}

PlatformFit FitPlatform(const cv::Mat& gray, const Block& block, double scale, int direction,
                        const std::vector<Vec2>& path, double thickness) {
  PlatformFit fit;
  const auto full = [&](double v) { return (v + 0.5) / scale - 0.5; };
  const cv::Rect& box = block.box;
  // On the reduced image: the block's highest row per column, its extreme column (towards the
  // overhang) per row.
  std::vector<int> top_of(block.mask.cols, -1), front_of(block.mask.rows, -1);
  for (int y = box.y; y < box.y + box.height; ++y) {
    const uchar* row = block.mask.ptr<uchar>(y);
    for (int x = box.x; x < box.x + box.width; ++x) {
      if (!row[x]) continue;
      if (top_of[x] < 0) top_of[x] = y;
      if (front_of[y] < 0 || (direction > 0 ? x > front_of[y] : x < front_of[y])) front_of[y] = x;
    }
  }
  // Coarse corner: the front face from the block's lower half (below where the strip may hang
  // along it), the top face just behind it.
  std::vector<double> fronts;
  for (int y = box.y + box.height / 2; y < box.y + box.height; ++y) {
    if (front_of[y] >= 0) fronts.push_back(front_of[y]);
  }
  if (fronts.size() < 5) {
    fit.why_not = "the block under the strip has no clear front face";
    return fit;
  }
  const double margin = std::max(3.0 * thickness, 12.0);
  const int across_min = std::clamp(static_cast<int>(std::lround(thickness)), 3, 12);
  const double reach_in = std::max(2.0 * thickness, 8.0),
               reach_out = std::max(3.0 * thickness, 12.0);
  const double front_x = full(Median(fronts));
  const auto column = [&](double x_full) {
    return std::clamp(static_cast<int>(std::lround((x_full + 0.5) * scale - 0.5)), box.x,
                      box.x + box.width - 1);
  };
  const auto row_of = [&](double y_full) {
    return std::clamp(static_cast<int>(std::lround((y_full + 0.5) * scale - 0.5)), box.y,
                      box.y + box.height - 1);
  };
  const int behind = column(front_x - direction * margin);
  if (top_of[behind] < 0) {
    fit.why_not = "the block under the strip has no clear top face";
    return fit;
  }
  const Vec2 corner0(front_x, full(top_of[behind]));
  // Does the strip lie on the block (a platform, whatever the measurement below makes of it)?
  // It does if its centre line runs just above the block's top for a stretch behind the corner;
  // a strip leaving a clamp starts at the clamp's face. The top on the reduced image lies below
  // the strip's zone (a thickness and a reduced pixel or two): a generous tolerance.
  int on_top = 0;
  for (const Vec2& p : path) {
    if ((p.x() - corner0.x()) * direction > -margin) continue;
    const int x = column(p.x());
    if (top_of[x] < 0) continue;
    const double above = full(top_of[x]) - p.y();
    if (above >= 0.0 && above <= 3.0 * thickness + 3.0 / scale) ++on_top;
  }
  fit.under_strip = on_top >= std::max(2.0 * thickness, 20.0);  // path points are 1 px apart

  // The faces are measured by scans across them, each averaged over `across` px along the
  // face and kept that far clear of the corner. A faint face under heavy noise (light that
  // makes the block almost as light as the background) scatters the steps found; the scans are
  // then repeated with four times the average (a face tilted by 12° shifts by a fifth of that
  // across the average, symmetrically: a blur, not a bias).
  std::vector<Vec2> top_pts, front_pts;  // (x, y) and (y, x)
  double a = 0, b = 0, c = 0, d = 0, rms_top = 1e9, rms_front = 1e9;
  int kept_top = 0, kept_front = 0;
  const auto straight = [&] {
    return rms_top <= 1.5 && rms_front <= 1.5 && kept_top >= 0.6 * top_pts.size() &&
           kept_front >= 0.6 * front_pts.size();
  };
  for (const int across : {across_min, std::min(4 * across_min, 40)}) {
    // Top face: vertical scans from inside the block upwards, spread over its far part.
    const double x_far = direction > 0 ? full(box.x) + 3.0 + across
                                       : full(box.x + box.width - 1) - 3.0 - across;
    const double x_near = corner0.x() - direction * (margin + across);
    top_pts.clear();
    if ((x_near - x_far) * direction > 10.0) {
      for (int k = 0; k < 60; ++k) {
        const double x = x_far + (x_near - x_far) * k / 59.0;
        const int top = top_of[column(x)];
        if (top < 0) continue;
        const Vec2 from(x, full(top) + reach_in), to(x, full(top) - reach_out);
        const double at = FirstStep(LineSamples(gray, from, to, across));
        if (at >= 0) top_pts.emplace_back(x, from.y() - 0.5 * at);
      }
    }
    // Front face: horizontal scans from inside the block outwards, below the corner.
    const double y_low = std::min(full(box.y + box.height - 1), gray.rows - 1.0) - 3.0 - across;
    const double y_high = corner0.y() + margin + across;
    front_pts.clear();
    if (y_low - y_high > 10.0) {
      for (int k = 0; k < 60; ++k) {
        const double y = y_high + (y_low - y_high) * k / 59.0;
        const int front = front_of[row_of(y)];
        if (front < 0) continue;
        const Vec2 from(full(front) - direction * reach_in, y),
            to(full(front) + direction * reach_out, y);
        const double at = FirstStep(LineSamples(gray, from, to, across));
        if (at >= 0) front_pts.emplace_back(y, from.x() + direction * 0.5 * at);
      }
    }
    if (top_pts.size() < 10 || front_pts.size() < 10) break;
    rms_top = FitLineRobust(top_pts, &a, &b, &kept_top);
    rms_front = FitLineRobust(front_pts, &c, &d, &kept_front);
    if (straight()) break;
  }
  if (top_pts.size() < 10 || front_pts.size() < 10) {
    fit.why_not = "the block under the strip is too small to measure its top and front faces";
    return fit;
  }
  // Corner: y = a + b x and x = c + d y.
  const double x = (c + d * a) / (1.0 - d * b);
  fit.corner = Vec2(x, a + b * x);
  fit.top_angle = -std::atan(b);
  const double xf = top_pts.front().x();
  fit.top_far = Vec2(xf, a + b * xf);
  const double yl = front_pts.back().x();
  fit.front_low = Vec2(c + d * yl, yl);
  double nearest = 1e300;
  for (const Vec2& p : path) nearest = std::min(nearest, (p - fit.corner).norm());

  if (std::abs(std::atan(b)) > 20 * kDeg) {
    fit.why_not = "the block's top face is not horizontal (" +
                  std::to_string(static_cast<int>(std::lround(std::atan(b) / kDeg))) + "°)";
  } else if (std::abs(std::atan(d)) > 30 * kDeg) {
    fit.why_not = "the block's front face is not vertical";
  } else if (!straight()) {
    fit.why_not = "the block's faces are not straight";
  } else if (nearest > std::max(2.0 * thickness, 10.0) + 3.0) {
    fit.why_not = "the strip does not pass over the block's corner";
  } else {
    fit.found = true;
  }
  return fit;
}

}  // namespace textile::extract_internal
