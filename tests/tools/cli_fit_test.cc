// `textile fit` through the real executable: profiles made by `textile synth-profile` from a
// known material are fitted back, and the fitted material must reproduce the known moment
// curve; bad input is refused with exit 2, failed computations exit 3, and in both cases no
// output is written or replaced (docs/spec/cli.md).

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "../fit/synthetic_photo.h"
#include "run_cli.h"
#include "textile/fit/law_error.h"
#include "textile/sim/law/material.h"

namespace textile {
namespace {

using testing::CountLines;
using testing::ReadAll;
using testing::Scratch;
namespace fs = std::filesystem;

const std::string kFig8 = "samples/materials/pabst-fig8.json";
const std::string kInterlining = "samples/materials/pabst-interlining.json";
constexpr double kFig8Gsm = 200.0;  // areal density of pabst-fig8.json [g/m²]

using testing::Textile;

std::string Quote(const fs::path& p) { return "'" + p.string() + "'"; }

std::set<std::string> Listing(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

// Synthetic profiles of `material` at the given overhangs into `dir`; returns the paths,
// shell-quoted and space-separated, ready for `textile fit`.
std::string Synth(const std::string& material, const std::string& overhangs, const fs::path& dir,
                  const std::string& extra = "") {
  const auto r = Textile("synth-profile --material " + material + " --overhang-mm " + overhangs +
                         " -o " + Quote(dir) + " --json " + extra);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::string paths;
  const auto j = nlohmann::json::parse(r.out);
  for (const auto& p : j.at("profiles")) {
    paths += Quote(p.at("path").get<std::string>()) + " ";
  }
  return paths;
}

// Writes a profile CSV through the points (x, y) [mm], s the running sum of the chords.
void WriteProfile(const fs::path& file, const std::vector<std::array<double, 2>>& xy) {
  std::ofstream f(file);
  f << "s_mm,x_mm,y_mm\n";
  double s = 0.0;
  for (size_t i = 0; i < xy.size(); ++i) {
    if (i > 0) s += std::hypot(xy[i][0] - xy[i - 1][0], xy[i][1] - xy[i - 1][1]);
    f << s << ',' << xy[i][0] << ',' << xy[i][1] << '\n';
  }
}

// A strip of length_mm sticking straight out, not sagging at all (y = 0): stiffer than any
// fabric the fit can resolve.
fs::path StraightHorizontal(const fs::path& dir, double length_mm) {
  std::vector<std::array<double, 2>> xy;
  for (int i = 0; i <= 30; ++i) xy.push_back({length_mm * i / 30.0, 0.0});
  const fs::path file = dir / "straight-horizontal.csv";
  WriteProfile(file, xy);
  return file;
}

// A 49 mm strip hanging straight down from the edge (x = 0): no bending stiffness at all, the
// limp limit; no law of a strip that has any can produce it.
fs::path HangingVertical(const fs::path& dir) {
  std::vector<std::array<double, 2>> xy;
  for (int i = 0; i < 50; ++i) xy.push_back({0.0, -1.0 * i});
  const fs::path file = dir / "hanging-vertical.csv";
  WriteProfile(file, xy);
  return file;
}

// M [gf·cm/cm] of a material at curvatures [1/cm], through `textile law --json`.
std::vector<double> Moments(const fs::path& material, const std::vector<double>& kappa_per_cm) {
  std::string args = "law --material " + Quote(material) + " --json --kappa";
  for (double k : kappa_per_cm) args += " " + std::to_string(k);
  const auto r = Textile(args);
  EXPECT_EQ(r.exit_code, 0) << material << ": " << r.err;
  std::vector<double> m;
  if (r.exit_code != 0) return m;
  const auto j = nlohmann::json::parse(r.out);
  for (const auto& p : j.at("law").at("points")) {
    m.push_back(p.at("M_gfcm_per_cm").get<double>());
  }
  return m;
}


// Fits the noise-free fig8 profiles with `method` and checks the material file and its report;
// the fitted M must match the truth within `tolerance` (relative) at the given fractions of
// the largest curvature in the data. Returns the report.
nlohmann::json FitRoundTrip(const std::string& method, const fs::path& dir, double tolerance,
                            const std::vector<double>& kappa_fractions) {
  const std::string profiles = Synth(kFig8, "40 60 80", dir / "profiles");
  const fs::path material = dir / "fitted.json";
  const auto r =
      Textile("fit " + profiles + "--gsm 200 --method " + method + " -o " + Quote(material));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("wrote " + material.string()), std::string::npos) << r.out;
  if (r.exit_code != 0) return {};

  nlohmann::json j;
  EXPECT_NO_THROW(j = nlohmann::json::parse(ReadAll(material))) << ReadAll(material);
  EXPECT_EQ(j.at("areal_density_gsm").get<double>(), kFig8Gsm);
  EXPECT_EQ(j.at("bending").at("units"), "kes");
  for (const char* k : {"b1", "b2", "c1"}) EXPECT_TRUE(j["bending"].at(k).is_number()) << k;
  // A fit measures bending, not the membrane: the file claims none (each simulation of it takes
  // the documented defaults and names them).
  EXPECT_FALSE(j.contains("stretch")) << j.dump(1);
  const nlohmann::json& fit = j.at("fit");
  for (const char* k : {"method", "b1_sd", "b2_sd", "c1_sd", "rms_mm", "bending_length_mm",
                        "flexural_rigidity_uNm", "b2_observed"}) {
    EXPECT_TRUE(fit.contains(k)) << "fit report lacks " << k << ": " << fit.dump(1);
  }
  EXPECT_EQ(fit.at("method"), method);
  EXPECT_TRUE(fit.at("b2_observed").is_boolean());
  // Classic outputs are self-consistent: G = ρ g c³ (docs/spec/cantilever.md), 1e-9 for rounding.
  const double c = fit.at("bending_length_mm").get<double>() * 1e-3;
  const double g_uNm = kFig8Gsm * 1e-3 * 9.80665 * c * c * c * 1e6;
  EXPECT_NEAR(fit.at("flexural_rigidity_uNm").get<double>(), g_uNm, 1e-9 * g_uNm);
  // The bending length of fig8 is about 17 mm (samples/materials/pabst-fig8.json).
  EXPECT_NEAR(c * 1e3, 17.0, 1.0);

  // The fitted material is readable by `textile law`, and its moment curve matches the
  // truth on the curvatures the data reach.
  const double kmax = fit.at("kappa_max_per_cm").get<double>();
  EXPECT_GT(kmax, 1.0);  // fig8 at 80 mm bends to ~1.8 /cm at the edge
  std::vector<double> kappa;
  for (double f : kappa_fractions) kappa.push_back(f * kmax);
  const auto fitted = Moments(material, kappa);
  const auto truth = Moments(fs::path(TEXTILE_SOURCE_DIR) / kFig8, kappa);
  EXPECT_EQ(fitted.size(), kappa.size());
  for (size_t i = 0; i < fitted.size() && i < truth.size(); ++i) {
    EXPECT_NEAR(fitted[i], truth[i], tolerance * std::abs(truth[i]))
        << method << " at κ = " << kappa[i] << " /cm";
  }
  EXPECT_EQ(Listing(dir), (std::set<std::string>{"profiles", "fitted.json"}));  // no temp files
  return fit;
}

TEST(CliFit, DirectRoundTripRecoversTheMomentCurve) {
  // Noise-free profiles written with 1 nm resolution: the direct fit recovers b1, b2, c1 to
  // ~1e-5; 0.5 % is the acceptance of the brief, far above that.
  const auto fit =
      FitRoundTrip("direct", Scratch("cli_fit_direct"), 0.005, {0.05, 0.25, 0.5, 0.75, 1.0});
  ASSERT_FALSE(fit.is_null());
  for (const char* k : {"b1_sd", "b2_sd", "c1_sd"}) EXPECT_TRUE(fit.at(k).is_number()) << k;
  EXPECT_LT(fit.at("rms_mm").get<double>(), 0.01);
  EXPECT_TRUE(fit.at("b2_observed").get<bool>());  // fig8's κ0 = 0.59 /cm < κmax
}

TEST(CliFit, ClappRoundTripRecoversTheMomentCurve) {
  // Clapp's order-5 polynomial φ(r) smooths the edge curvature: on these profiles M is low by
  // ~3 % from a quarter of κmax on (and by ~6 % near κ = 0, which is why the check starts at
  // κmax/4). 5 % is the acceptance for this classic method.
  const auto fit = FitRoundTrip("clapp", Scratch("cli_fit_clapp"), 0.05, {0.25, 0.5, 0.75, 1.0});
  ASSERT_FALSE(fit.is_null());
  EXPECT_LT(fit.at("rms_mm").get<double>(), 0.5);
}

// Synthetic noisy fig8 profiles (40, 60, 80 mm) turned by `deg` about the edge and shifted by
// `dy_mm`, as a rig that is not level or an origin off the platform would give them; returns
// the paths, shell-quoted, ready for `textile fit`.
std::string TurnedProfiles(const fs::path& dir, double deg, double dy_mm) {
  const auto r = Textile("synth-profile --material " + kFig8 + " --overhang-mm 40 60 80 -o " +
                         Quote(dir / "raw") + " --noise-mm 0.1 --json");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  if (r.exit_code != 0) return "";
  const double a = deg * M_PI / 180.0;
  std::string paths;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  for (const auto& p : j.at("profiles")) {
    std::istringstream in(ReadAll(p.at("path").get<std::string>()));
    std::vector<std::array<double, 2>> xy;
    std::string line;
    while (std::getline(in, line)) {
      double s, x, y;
      if (line.empty() || line[0] == '#' ||
          std::sscanf(line.c_str(), "%lf,%lf,%lf", &s, &x, &y) != 3)
        continue;
      xy.push_back({std::cos(a) * x - std::sin(a) * y, std::sin(a) * x + std::cos(a) * y + dy_mm});
    }
    const fs::path out = dir / fs::path(p.at("path").get<std::string>()).filename();
    WriteProfile(out, xy);
    paths += Quote(out) + " ";
  }
  return paths;
}

// Law and report of `textile fit` on `profiles` (exit 0 asserted by the caller).
struct FitRun {
  testing::CliResult run;
  nlohmann::json material;
};
FitRun FitTo(const std::string& profiles, const fs::path& material) {
  FitRun f{Textile("fit " + profiles + "--gsm 200 -o " + Quote(material)), {}};
  if (f.run.exit_code == 0) f.material = nlohmann::json::parse(ReadAll(material));
  return f;
}

// A rig that is not level: without a rotation a tilt of half a degree sent b1 2.5× off and one
// degree c1 to -800 gf·cm² (rms hardly worse, exit 0). The fit now tries a rotation too, keeps
// it when the data ask for it and says so; level profiles keep the fit without it. (0.25°: a
// review found 0.2-0.35° undetected by the first test, five sd on the plain rms, with b1 8-78 %
// high.)
TEST(CliFit, ATiltedRigIsFittedWithItsRotationAndSaysSo) {
  const auto dir = Scratch("cli_fit_tilt");
  const FitRun level = FitTo(TurnedProfiles(dir / "level", 0.0, 0.0), dir / "level.json");
  ASSERT_EQ(level.run.exit_code, 0) << level.run.err;
  EXPECT_EQ(level.run.out.find("note:"), std::string::npos) << level.run.out;
  EXPECT_FALSE(level.material.at("fit").at("rotation_fitted").get<bool>());
  EXPECT_TRUE(level.material.at("fit").at("note").is_null());
  const double b1 = level.material.at("bending").at("b1").get<double>();
  for (double deg : {0.25, 0.6, -1.0}) {
    const FitRun tilted =
        FitTo(TurnedProfiles(dir / std::to_string(deg), deg, 0.0), dir / "tilted.json");
    ASSERT_EQ(tilted.run.exit_code, 0) << tilted.run.err;
    EXPECT_NE(tilted.run.out.find("note: the profiles are tilted by"), std::string::npos)
        << tilted.run.out;
    const nlohmann::json& fit = tilted.material.at("fit");
    EXPECT_TRUE(fit.at("rotation_fitted").get<bool>());
    EXPECT_NEAR(fit.at("rotation_deg").get<double>(), deg, 0.1);
    EXPECT_NE(fit.at("note").get<std::string>().find("tilted"), std::string::npos);
    EXPECT_NEAR(tilted.material.at("bending").at("b1").get<double>(), b1, 0.05 * b1);
    EXPECT_LT(std::abs(tilted.material.at("bending").at("c1").get<double>()), 0.1);
  }
}

// Profiles whose y = 0 is not the platform's top: the fitted offset absorbs the shift (the law
// is the same) and a note says the offset is no half thickness.
TEST(CliFit, AnOffsetThatIsNoHalfThicknessGetsANote) {
  const auto dir = Scratch("cli_fit_offset_note");
  const FitRun level = FitTo(TurnedProfiles(dir / "level", 0.0, 0.0), dir / "level.json");
  ASSERT_EQ(level.run.exit_code, 0) << level.run.err;
  const FitRun low = FitTo(TurnedProfiles(dir / "low", 0.0, -20.0), dir / "low.json");
  ASSERT_EQ(low.run.exit_code, 0) << low.run.err;
  EXPECT_NE(low.run.out.find("note: the fitted offset at the edge, -"), std::string::npos)
      << low.run.out;
  EXPECT_NEAR(low.material.at("fit").at("offset_mm").get<double>(), -20.0, 0.5);
  for (const char* k : {"b1", "b2", "c1"}) {
    const double want = level.material.at("bending").at(k).get<double>();
    EXPECT_NEAR(low.material.at("bending").at(k).get<double>(), want, 1e-3 * std::abs(want)) << k;
  }
}

TEST(CliFit, JsonPrintsOneObjectWithTheMaterial) {
  const auto dir = Scratch("cli_fit_json");
  const std::string profiles = Synth(kFig8, "50 70", dir / "profiles");
  const fs::path material = dir / "fitted.json";
  const auto r = Textile("fit " + profiles + "--gsm 200 --name 'json strip' -o " + Quote(material) +
                         " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json j;
  ASSERT_NO_THROW(j = nlohmann::json::parse(r.out)) << "stdout is not one JSON object:\n" << r.out;
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j.at("material_file"), material.string());
  EXPECT_EQ(j.at("material"), nlohmann::json::parse(ReadAll(material)));
  EXPECT_EQ(j["material"].at("name"), "json strip");
  EXPECT_EQ(j["material"].at("fit").at("method"), "direct");
}

TEST(CliFit, PlotWritesAPng) {
  const auto dir = Scratch("cli_fit_plot");
  const std::string profiles = Synth(kFig8, "40 60 80", dir / "profiles", "--noise-mm 0.05");
  const fs::path png = dir / "fit.png";
  for (const char* method : {"direct", "clapp"}) {
    fs::remove(png);
    const auto r = Textile("fit " + profiles + "--gsm 200 --method " + method + " -o " +
                           Quote(dir / "fitted.json") + " --plot " + Quote(png));
    ASSERT_EQ(r.exit_code, 0) << method << ": " << r.err;
    ASSERT_TRUE(fs::exists(png)) << method;
    EXPECT_GT(fs::file_size(png), 20000u) << method;  // two panels of curves, not a blank image
    EXPECT_EQ(ReadAll(png).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << method;
  }
  EXPECT_EQ(Listing(dir), (std::set<std::string>{"profiles", "fitted.json", "fit.png"}));
}

TEST(CliFit, BadProfilesExit2NamingTheFile) {
  struct Case {
    const char* file;
    const char* fragment;
  };
  const auto dir = Scratch("cli_fit_bad_profiles");
  const std::string good = Synth(kFig8, "60", dir / "profiles");
  const fs::path out = dir / "never.json";
  for (const Case& c :
       {Case{"empty.csv", "empty profile"}, Case{"binary.csv", "expected the header"},
        Case{"wrong-header.csv", "expected the header"},
        Case{"no-header.csv", "expected the header"}, Case{"too-few.csv", "at least 10"},
        Case{"non-increasing-s.csv", "must increase strictly"}, Case{"nan.csv", "NaN or infinite"},
        Case{"rises-above.csv", "above the platform"}, Case{"folds-back.csv", "folds back"},
        Case{"not-a-number.csv", "is not a number"}, Case{"two-columns.csv", "expected 3 values"},
        Case{"does-not-exist.csv", "cannot open"}}) {
    const std::string path = std::string("tests/data/profiles/") + c.file;
    // Alone and after a good profile: the bad one is named either way.
    for (const std::string& inputs : {path, good + path}) {
      for (const char* method : {"direct", "clapp"}) {
        const auto r =
            Textile("fit " + inputs + " --gsm 200 --method " + method + " -o " + Quote(out));
        testing::ExpectRefused(r, "error: " + path, inputs + " (" + method + ")");
        EXPECT_NE(r.err.find(c.fragment), std::string::npos) << c.file << ": " << r.err;
      }
    }
  }
  EXPECT_EQ(Listing(dir), std::set<std::string>{"profiles"}) << "a refused fit wrote something";
}

TEST(CliFit, BadNumbersExit2NamingTheFlag) {
  struct Case {
    const char* args;
    const char* flag;
  };
  const auto dir = Scratch("cli_fit_bad_numbers");
  const std::string profiles = Synth(kFig8, "60", dir / "profiles");
  const fs::path out = dir / "never.json";
  for (const Case& c :
       {Case{"--gsm 0", "--gsm"}, Case{"--gsm -200", "--gsm"}, Case{"--gsm nan", "--gsm"},
        Case{"--gsm inf", "--gsm"}, Case{"--gsm 1e9", "--gsm"}, Case{"--gsm heavy", "--gsm"},
        Case{"", "--gsm"},  // required
        Case{"--gsm 200 --thickness-mm 0", "--thickness-mm"},
        Case{"--gsm 200 --thickness-mm 50", "--thickness-mm"},
        Case{"--gsm 200 --robust-mm -1", "--robust-mm"},
        Case{"--gsm 200 --robust-mm nan", "--robust-mm"},
        Case{"--gsm 200 --method foo", "--method"}}) {
    const auto r = Textile("fit " + profiles + c.args + " -o " + Quote(out));
    testing::ExpectRefused(r, c.flag, c.args);
  }
  EXPECT_EQ(Listing(dir), std::set<std::string>{"profiles"});
}

TEST(CliFit, NegativeOrNanThicknessIsRefused) {
  // --thickness-mm is a measured thickness: -1 or nan is a typo, not "fit the offset".
  const auto dir = Scratch("cli_fit_bad_thickness");
  const std::string profiles = Synth(kFig8, "60", dir / "profiles");
  const fs::path out = dir / "never.json";
  for (const char* t : {"-1", "nan", "-inf"}) {
    const auto r =
        Textile("fit " + profiles + "--gsm 200 --thickness-mm " + t + " -o " + Quote(out));
    testing::ExpectRefused(r, "--thickness-mm", std::string("--thickness-mm ") + t);
    EXPECT_FALSE(fs::exists(out)) << "--thickness-mm " << t;
    fs::remove(out);
  }
}

TEST(CliFit, UnwritableOutputExit2AndWritesNothing) {
  const auto dir = Scratch("cli_fit_unwritable");
  const std::string profiles = Synth(kFig8, "60", dir / "profiles");
  const fs::path regular = dir / "regular-file";
  std::ofstream(regular) << "keep me\n";
  for (const fs::path& out :
       {fs::path("/nonexistent-dir/fitted.json"), fs::path("/proc/forbidden.json"),
        regular / "fitted.json", dir / "profiles" /* a folder */}) {
    const auto r = Textile("fit " + profiles + "--gsm 200 -o " + Quote(out));
    testing::ExpectRefused(r, out.string(), out.string());
  }
  EXPECT_EQ(ReadAll(regular), "keep me\n");
  EXPECT_EQ(Listing(dir), (std::set<std::string>{"profiles", "regular-file"}));
  EXPECT_EQ(Listing(dir / "profiles").size(), 1u);
}

TEST(CliFit, UnwritablePlotExit2AndWritesNoMaterial) {
  const auto dir = Scratch("cli_fit_unwritable_plot");
  const std::string profiles = Synth(kFig8, "60", dir / "profiles");
  const fs::path regular = dir / "regular-file";
  std::ofstream(regular) << "keep me\n";
  const fs::path material = dir / "fitted.json";
  for (const fs::path& plot :
       {fs::path("/nonexistent-dir/fit.png"), fs::path("/proc/forbidden.png"), regular / "fit.png",
        dir / "profiles" /* a folder */}) {
    const auto r =
        Textile("fit " + profiles + "--gsm 200 -o " + Quote(material) + " --plot " + Quote(plot));
    testing::ExpectRefused(r, plot.string(), plot.string());
    EXPECT_FALSE(fs::exists(material))
        << plot << ": the material was written although the plot failed";
  }
  EXPECT_EQ(Listing(dir), (std::set<std::string>{"profiles", "regular-file"}));
}

TEST(CliFit, DifferentStripsExit2) {
  // An apparel fabric (fig8) and a stiff interlining at the same overhangs: no single law fits
  // both, each alone fits to the noise. That is bad input (exit 2), not a failed fit.
  const auto dir = Scratch("cli_fit_different_strips");
  const std::string profiles = Synth(kFig8, "40 60 80", dir / "profiles", "--noise-mm 0.05") +
                               Synth(kInterlining, "40 60 80", dir / "profiles", "--noise-mm 0.05");
  const fs::path out = dir / "never.json";
  const auto r = Textile("fit " + profiles + "--gsm 200 -o " + Quote(out));
  testing::ExpectRefused(r, "different strips", "fig8 + interlining");
  EXPECT_NE(r.err.find((dir / "profiles").string()), std::string::npos)
      << "names no profile: " << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CliFit, ClappDoesNotWriteALawForDifferentStrips) {
  // Clapp's regression cannot tell mixed strips apart by itself, but it must not write a law
  // that re-simulates the profiles centimetres off (or that `textile law` refuses): it has to
  // fail, as bad input or as a failed computation.
  const auto dir = Scratch("cli_fit_different_strips_clapp");
  const std::string profiles = Synth(kFig8, "40 60 80", dir / "profiles", "--noise-mm 0.05") +
                               Synth(kInterlining, "40 60 80", dir / "profiles", "--noise-mm 0.05");
  const fs::path out = dir / "never.json";
  const auto r = Textile("fit " + profiles + "--gsm 200 --method clapp -o " + Quote(out));
  EXPECT_TRUE(r.exit_code == 2 || r.exit_code == 3) << "exit " << r.exit_code << "\n" << r.out;
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(out)) << ReadAll(out);
}

TEST(CliFit, FailedRunKeepsTheOldMaterial) {
  const auto dir = Scratch("cli_fit_keep");
  const std::string profiles = Synth(kFig8, "50 70", dir / "profiles");
  const std::string hanging = Quote(HangingVertical(dir / "profiles"));
  const fs::path material = dir / "fitted.json";
  const auto good = Textile("fit " + profiles + "--gsm 200 -o " + Quote(material));
  ASSERT_EQ(good.exit_code, 0) << good.err;
  const std::string before = ReadAll(material);
  ASSERT_GT(before.size(), 100u);
  struct Case {
    std::string args;
    int exit_code;
  };
  for (const Case& c :
       {Case{"tests/data/profiles/folds-back.csv --gsm 200", 2}, Case{profiles + "--gsm 0", 2},
        Case{profiles + "--gsm 200 --plot /nonexistent-dir/fit.png", 2},
        Case{hanging + " --gsm 200", 3}, Case{hanging + " --gsm 200 --method clapp", 3}}) {
    const auto r = Textile("fit " + c.args + " -o " + Quote(material));
    EXPECT_EQ(r.exit_code, c.exit_code) << c.args << "\n" << r.err;
    EXPECT_TRUE(r.out.empty()) << c.args << ": " << r.out;
    EXPECT_EQ(ReadAll(material), before) << c.args << ": the good material was replaced";
  }
  EXPECT_EQ(Listing(dir), (std::set<std::string>{"profiles", "fitted.json"}));  // no temp files
}

TEST(CliFit, NoConvergenceExits3AndWritesNothing) {
  // A strip hanging straight down passes the profile checks, but no strip with a bending
  // stiffness makes it: the direct fit's elastica fails at the limp end of the bounds, and
  // Clapp's regression finds no law in the textile range. Both are failed computations.
  const auto dir = Scratch("cli_fit_no_convergence");
  const std::string hanging = Quote(HangingVertical(dir));
  for (const char* method : {"direct", "clapp"}) {
    const auto r = Textile("fit " + hanging + " --gsm 200 --method " + method + " -o " +
                           Quote(dir / "never.json") + " --plot " + Quote(dir / "never.png"));
    EXPECT_EQ(r.exit_code, 3) << method << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  EXPECT_EQ(Listing(dir), std::set<std::string>{"hanging-vertical.csv"});
}

TEST(CliFit, StraightHorizontalStripExits3) {
  // A 60 mm strip that does not sag at all: stiffer than anything the fit can resolve. The
  // stiffness bound must stop the fit with exit 3, not hand out the bound as the strip's
  // bending stiffness.
  const auto dir = Scratch("cli_fit_straight");
  const std::string straight = Quote(StraightHorizontal(dir, 60.0));
  for (const char* method : {"direct", "clapp"}) {
    const fs::path out = dir / (std::string(method) + ".json");
    const auto r =
        Textile("fit " + straight + " --gsm 200 --method " + method + " -o " + Quote(out));
    EXPECT_EQ(r.exit_code, 3) << method << "\n" << r.out << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << method << ": " << r.err;
    EXPECT_FALSE(fs::exists(out)) << method << ":\n" << ReadAll(out);
  }
}

TEST(CliFit, StripStifferThanTheTextileRangeFailsInOneLine) {
  // 1 m sticking straight out at 200 g/m²: Peirce's start is beyond the 1000 gf·cm the bounds
  // allow. Still a failed computation with one line for people, not the optimiser's internals.
  const auto dir = Scratch("cli_fit_too_stiff");
  const std::string straight = Quote(StraightHorizontal(dir, 1000.0));
  const fs::path out = dir / "never.json";
  const auto r = Textile("fit " + straight + " --gsm 200 -o " + Quote(out));
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.find("ParameterBlock"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CliFit, PhotoInputsNeedARigAndAreNamedWhenBad) {
  const auto dir = Scratch("cli_fit_photo_inputs");
  const std::string good = Synth(kFig8, "60", dir / "profiles");
  testing::PhotoScene blank;
  blank.width = 600;
  blank.height = 400;
  blank.strip = blank.background;  // nothing to find
  cv::imwrite((dir / "blank.png").string(), testing::Render(blank).gray);
  { std::ofstream(dir / "text.jpg") << "not a jpeg"; }
  const fs::path out = dir / "never.json";
  const std::string blank_png = Quote(dir / "blank.png");
  struct Case {
    std::string args;
    int code;
    std::string words;
  };
  const Case cases[] = {
      {good + blank_png, 2, "blank.png is a photo: give exactly one of --rig"},
      {good + blank_png + " --mm-per-px 0.1 --rig x.json", 2, "give exactly one of --rig"},
      {good + Quote(dir / "text.jpg") + " --mm-per-px 0.1", 2, "text.jpg: not a supported image"},
      {good + blank_png + " --mm-per-px 0.1 --trace side", 2, "--trace"},
      {good + blank_png + " --mm-per-px 0.1 --edge-px 1", 2, "--edge-px: expected X,Y"},
      {good + blank_png + " --mm-per-px 0.1", 3, "blank.png: "},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const auto r = Textile("fit " + c.args + " --gsm 200 -o " + Quote(out));
    EXPECT_EQ(r.exit_code, c.code) << r.err;
    EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.words), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST(CliFit, LargePhotosAreExtractedQuietlyUnlessProgressIsAsked) {
  // Photos over 4 MP get an "extracting ..." progress line, on stderr only when it is a terminal
  // or with --progress (as `textile extract`): a script's stderr of a good run stays empty.
  const auto dir = Scratch("cli_fit_large_photo");
  const fs::path photo = dir / "big.jpg", rig = dir / "big.rig-truth.json";
  const auto render = Textile("render-photo --material " + kFig8 + " --overhang-mm 60 -o " +
                              Quote(photo) + " --size 2400x1700 --difficulty easy");
  ASSERT_EQ(render.exit_code, 0) << render.err;
  ASSERT_GT(cv::imread(photo.string(), cv::IMREAD_GRAYSCALE).total(), 4e6);
  const std::string args = "fit " + Quote(photo) + " --rig " + Quote(rig) + " --gsm 200 -o ";
  const auto quiet = Textile(args + Quote(dir / "quiet.json"));
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");
  const auto verbose = Textile(args + Quote(dir / "verbose.json") + " --progress");
  ASSERT_EQ(verbose.exit_code, 0) << verbose.err;
  EXPECT_EQ(verbose.err, "extracting " + photo.string() + " ...\n");
  // The flag changes nothing but stderr: the same law.
  const Material a = ReadMaterial((dir / "quiet.json").string());
  const Material b = ReadMaterial((dir / "verbose.json").string());
  EXPECT_EQ(a.bending.b1(), b.bending.b1());
  EXPECT_EQ(a.bending.c1(), b.bending.c1());
}

TEST(CliFit, ShippedPhotosGiveTheExpectedLawAndTheTruthWithinOnePercent) {
  // samples/photos: rendered photos (medium level) of two of the paper's fabrics, their boards.
  // Calibrate on the board, fit the photos: the shipped expected law is reproduced, and the
  // moment curve is within 1 % of the truth (issue 4's target for fits from photos).
  struct Case {
    std::string fabric, overhangs, gsm, square;
  };
  const auto dir = Scratch("cli_fit_sample_photos");
  // The Fig. 8 fabric only (the interlining's photos are made and fitted the same way; one
  // fabric keeps the test short).
  for (const Case& c : {Case{"pabst-fig8", "040 060 080", "200", "8.5"}}) {
    SCOPED_TRACE(c.fabric);
    const std::string photos_dir = "samples/photos/";
    const fs::path rig = dir / (c.fabric + ".rig.json"), out = dir / (c.fabric + ".json");
    const auto cal = Textile("calibrate " + photos_dir + c.fabric + ".board.jpg --board 9x6 --square-mm " +
                             c.square + " -o " + Quote(rig));
    ASSERT_EQ(cal.exit_code, 0) << cal.err;
    std::string photos;
    std::stringstream in(c.overhangs);
    for (std::string L; in >> L;) photos += photos_dir + c.fabric + "_L" + L + "mm.jpg ";
    const auto r = Textile("fit " + photos + "--rig " + Quote(rig) + " --gsm " + c.gsm + " -o " + Quote(out));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const std::string src = TEXTILE_SOURCE_DIR;
    const Material got = ReadMaterial(out.string());
    const Material expected = ReadMaterial(src + "/samples/photos/" + c.fabric + ".fitted.json");
    const Material truth = ReadMaterial(src + "/samples/materials/" + c.fabric + ".json");
    const double kappa_max = got.fit["kappa_max_per_cm"].get<double>() * 100.0;
    // Optimiser precision, as for the shipped profiles (cli_samples_test.cc).
    EXPECT_LT(MomentCurveError(got.bending, expected.bending, kappa_max), 1e-4);
    EXPECT_LT(MomentCurveError(got.bending, truth.bending, kappa_max), 0.01);
    EXPECT_EQ(got.fit["photos"].size(), 3u);
  }
}

// The real photos of a technical fabric (Broberg et al., 1387 g/m²; not shipped with the
// project): photo -> fit -> validate with only the scale and the areal density. They failed
// ("did not converge", "ran into the bound b1 = 1e3 gf·cm", then the shell's solves at the
// round-off floor); their law lies far outside apparel (b1 thousands of gf·cm, a sharp knee),
// and Pabst's three constants do not follow it everywhere, which the fit now says.
TEST(CliFit, RealTechnicalFabricPhotosFitAndValidate) {
  const fs::path photos = fs::path(TEXTILE_SOURCE_DIR) / ".." / "shared" / "data" / "real-photos";
  if (!fs::exists(photos / "broberg-example.jpg") || !fs::exists(photos / "broberg-break.jpg")) {
    GTEST_SKIP() << photos << " is not available";
  }
  const fs::path dir = Scratch("cli_fit_real");
  for (const char* name : {"broberg-example", "broberg-break"}) {
    SCOPED_TRACE(name);
    const std::string photo = Quote(photos / (std::string(name) + ".jpg"));
    const fs::path fitted = dir / (std::string(name) + ".json");
    const auto f =
        Textile("fit " + photo + " --mm-per-px 0.1101 --gsm 1387 -o " + Quote(fitted));
    ASSERT_EQ(f.exit_code, 0) << f.err;
    EXPECT_NE(f.out.find("the law does not follow the data"), std::string::npos) << f.out;
    const Material m = ReadMaterial(fitted.string());
    EXPECT_GT(m.bending.b1_kes(), 1000.0);
    EXPECT_LT(m.bending.b2_kes(), 0.1 * m.bending.b1_kes());  // softening more than 10-fold
    const fs::path out = dir / (std::string(name) + "-validate");
    const auto v = Textile("validate " + photo + " --mm-per-px 0.1101 --gsm 1387 -o " + Quote(out));
    ASSERT_EQ(v.exit_code, 0) << v.err;
    EXPECT_TRUE(fs::exists(out / "validate.json"));
    EXPECT_NE(v.out.find("shell   : rms"), std::string::npos) << v.out;
  }
}

}  // namespace
}  // namespace textile
