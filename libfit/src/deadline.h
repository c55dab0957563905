#ifndef TEXTILE_FIT_SRC_DEADLINE_H_
#define TEXTILE_FIT_SRC_DEADLINE_H_

// The wall-clock time caps of the photo parsers and fits (ExtractOptions, CalibrateOptions and
// ClappOptions::max_seconds): a budget that starts when it is made and is read between stages.
// Not public API.

#include <chrono>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

namespace textile::fit_internal {

class Deadline {
 public:
  explicit Deadline(double max_seconds)
      : max_seconds_(max_seconds), start_(std::chrono::steady_clock::now()) {}

  double Elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  double Remaining() const { return max_seconds_ - Elapsed(); }

  // Once the cap is reached (a cap of 0 s at the first reading): "time cap of C s reached after
  // T s, <stage>", for the caller to prefix and end with what it gives up; before that, nothing.
  std::optional<std::string> Reached(std::string_view stage) const {
    const double t = Elapsed();
    if (t < max_seconds_) return std::nullopt;
    std::ostringstream m;
    m.precision(3);
    m << "time cap of " << max_seconds_ << " s reached after " << t << " s, " << stage;
    return m.str();
  }

 private:
  double max_seconds_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace textile::fit_internal

#endif  // TEXTILE_FIT_SRC_DEADLINE_H_
