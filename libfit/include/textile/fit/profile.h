#ifndef TEXTILE_FIT_PROFILE_H_
#define TEXTILE_FIT_PROFILE_H_

// A measured cantilever profile in the bending plane (docs/spec/cantilever.md, "Frame"): origin at
// the platform edge, x towards the overhang, y up (a hanging strip has y < 0), s the arc length
// from the edge. Files are CSV with the header `s_mm,x_mm,y_mm`; inside, metres.
//
//   textile::Profile p = textile::ReadProfileCsv("strip_60mm.profile.csv");
//   double overhang = p.s.back();                       // [m]
//   std::string csv = textile::ProfileToCsv(p);         // back to mm

#include <string>
#include <vector>

namespace textile {

struct Profile {
  std::string source;         // file name or description, for messages
  std::vector<double> s;      // #N arc length from the edge [m], strictly increasing
  std::vector<double> x, y;   // #N positions [m]
  size_t size() const { return s.size(); }
};

// Fewest points a profile may have to be fitted.
inline constexpr int kMinProfilePoints = 10;

// Parses CSV text (header s_mm,x_mm,y_mm; comma separated; '#' comments and blank lines are
// skipped) and validates it with CheckProfile. Throws InputError "<source>:<line>: <problem>".
Profile ParseProfileCsv(const std::string& text, const std::string& source);
// Reads and parses a file; throws InputError if it cannot be read.
Profile ReadProfileCsv(const std::string& path);
// Validates a profile: enough points, finite, s strictly increasing, no point far above the
// platform, no folding back. Throws InputError naming the source and the first problem.
void CheckProfile(const Profile& profile);
// CSV text with the header s_mm,x_mm,y_mm, 6 decimals (1 nm).
std::string ProfileToCsv(const Profile& profile);
// The points' own scatter [m]: the median distance of each point from the line through its
// neighbours, as a σ (÷ √1.5, what white noise σ gives there, × 1.4826 for the median), so
// that fibres do not count. A fit's rms far above it is a law that does not follow the data.
double ProfilePointScatter(const Profile& profile);

}  // namespace textile

#endif  // TEXTILE_FIT_PROFILE_H_
