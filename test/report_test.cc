// report.html (apps/report.h) as a person sees it: written by calibrate on the shared KITTI frames
// and on a simulated drive, self-contained, opened in headless Chromium (Debian's `chromium`,
// installed by scripts/setup) with no console error and every image decoded; `stcalib report`
// writes the same page again, and refuses a folder that is no run.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "test/test_util.h"

namespace stcalib {
namespace {

using ::testing::HasSubstr;

using RunResult = testing::CommandResult;
RunResult Run(const std::string& command) { return testing::RunCommand(command); }

RunResult Stcalib(const std::string& args) { return Run(std::string(STCALIB_BINARY) + " " + args); }

constexpr char kChromium[] = "/usr/bin/chromium";

// Chromium is there, or the test skips (outside CI) or fails (CI sets STCALIB_REQUIRE_BROWSER).
#define STCALIB_REQUIRE_CHROMIUM()                                                        \
  if (!std::filesystem::exists(kChromium)) {                                              \
    if (std::getenv("STCALIB_REQUIRE_BROWSER") != nullptr) {                              \
      FAIL() << kChromium << " is missing, and CI must test the report in a browser: "    \
             << "scripts/setup installs Debian's chromium";                               \
    }                                                                                     \
    GTEST_SKIP() << kChromium << " is missing: the report's browser test needs Debian's " \
                 << "chromium (scripts/setup installs it)";                               \
  }

// Checks one run folder's report.html: self-contained, every section there, and in headless
// Chromium no console message and every image decoded (the page's own load handler counts
// them); saves a screenshot beside it.
void CheckReportInBrowser(const std::string& run_dir,
                          const std::vector<const char*>& sections = {"verdict", "estimate",
                                                                      "overlays", "curves",
                                                                      "time-forward", "run"},
                          int min_images = 7) {
  const std::string path = run_dir + "/report.html";
  const std::string html = testing::ReadFile(path);
  ASSERT_FALSE(html.empty()) << path;
  EXPECT_EQ(html.find("http://"), std::string::npos) << "the report fetches nothing";
  EXPECT_EQ(html.find("https://"), std::string::npos) << "the report fetches nothing";
  for (const char* id : sections) {
    EXPECT_THAT(html, HasSubstr(std::string("<section id=\"") + id + "\"")) << id;
  }
  int images = 0;
  for (size_t at = html.find("<img "); at != std::string::npos; at = html.find("<img ", at + 1)) {
    ++images;
    const size_t src = html.find("src=\"", at);
    ASSERT_NE(src, std::string::npos);
    EXPECT_EQ(html.compare(src + 5, 14, "data:image/png"), 0) << "an image not inlined";
  }
  EXPECT_GE(images, min_images);

  const std::string chromium = std::string(kChromium) +
                               " --headless --no-sandbox --disable-gpu --enable-logging=stderr "
                               "--v=0 --hide-scrollbars ";
  const RunResult dom = Run(chromium + "--dump-dom file://" + path);
  ASSERT_EQ(dom.exit_code, 0) << dom.output.substr(0, 2000);
  const std::string decoded =
      "data-images=\"" + std::to_string(images) + "/" + std::to_string(images) + "\"";
  EXPECT_THAT(dom.output, HasSubstr(decoded)) << "not every image decoded";
  EXPECT_THAT(dom.output, ::testing::Not(HasSubstr(":CONSOLE")))
      << "a console message: " << dom.output.substr(0, 2000);
  const std::string screenshot = run_dir + "/report_screenshot.png";
  const RunResult shot =
      Run(chromium + "--window-size=1300,1600 --screenshot=" + screenshot + " file://" + path);
  EXPECT_EQ(shot.exit_code, 0) << shot.output.substr(0, 2000);
  EXPECT_GT(std::filesystem::exists(screenshot) ? std::filesystem::file_size(screenshot) : 0,
            10000u);
}

TEST(Report, SharedFramesRunOpensInABrowser) {
  STCALIB_REQUIRE_KITTI();
  STCALIB_REQUIRE_CHROMIUM();
  testing::ScopedTempDir tmp;
  const std::string out = tmp.path() + "/run";
  const RunResult r = Stcalib(
      "calibrate --flagfile=" STCALIB_SOURCE_DIR "/configs/kitti.flags --drive=" +
      testing::KittiDriveDir() + " --perturb_rot_deg=2 --seed=1 --num_frames=12 --out=" + out);
  ASSERT_NE(r.exit_code, 2) << r.output;
  CheckReportInBrowser(out);
  // The version and the command are the run's.
  const nlohmann::json result = nlohmann::json::parse(testing::ReadFile(out + "/result.json"));
  EXPECT_THAT(result["command"].get<std::string>(), HasSubstr("calibrate --flagfile="));
  EXPECT_THAT(testing::ReadFile(out + "/report.html"),
              HasSubstr(result["stcalib_version"].get<std::string>()));
}

// check --out writes its own page: the answer, the per-axis table and the frames at the checked
// calibration.
TEST(Report, CheckRunOpensInABrowser) {
  STCALIB_REQUIRE_KITTI();
  STCALIB_REQUIRE_CHROMIUM();
  testing::ScopedTempDir tmp;
  const std::string out = tmp.path() + "/check";
  const RunResult r =
      Stcalib("check --drive=" + testing::KittiDriveDir() + " --num_frames=9 --out=" + out);
  ASSERT_NE(r.exit_code, 2) << r.output;
  CheckReportInBrowser(out, {"verdict", "axes", "overlays", "run"}, 4);
  EXPECT_THAT(testing::ReadFile(out + "/report.html"), HasSubstr("calib_velo_to_cam.txt"));
}

TEST(Report, SimulatedRunOpensInABrowserAndIsWrittenAgainAlike) {
  STCALIB_REQUIRE_CHROMIUM();
  testing::ScopedTempDir tmp;
  ASSERT_EQ(Stcalib("simulate --out=" + tmp.path() + "/sim --frames=8 --seed=3").exit_code, 0);
  std::string drive;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(tmp.path() + "/sim")) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory() && name.size() > 5 && name.substr(name.size() - 5) == "_sync") {
      drive = entry.path().string();
    }
  }
  ASSERT_FALSE(drive.empty());
  const std::string out = tmp.path() + "/run";
  const RunResult r =
      Stcalib("calibrate --flagfile=" STCALIB_SOURCE_DIR "/configs/sim.flags --drive=" + drive +
              " --perturb_rot_deg=2 --perturb_trans_m=0.05 --out=" + out);
  ASSERT_NE(r.exit_code, 2) << r.output;
  CheckReportInBrowser(out);
  const std::string first = testing::ReadFile(out + "/report.html");
  const RunResult again = Stcalib("report " + out);
  EXPECT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(testing::ReadFile(out + "/report.html"), first) << "report RUN_DIR wrote another page";
}

TEST(Report, RefusesAFolderThatIsNoRunOrOfAnotherVersion) {
  testing::ScopedTempDir tmp;
  RunResult r = Stcalib("report " + tmp.path());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.output, HasSubstr(tmp.path() + "/result.json: missing (and no check.json)"));
  EXPECT_FALSE(std::filesystem::exists(tmp.path() + "/report.html"));
  // A result.json without the keys the page shows: each is named, nothing is written.
  testing::WriteFile(tmp.path() + "/result.json",
                     "{\"converged\": true, \"reason\": \"converged\"}");
  r = Stcalib("report " + tmp.path());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.output, HasSubstr("result.json: no stcalib_version, command"));
  EXPECT_THAT(r.output, HasSubstr("another stcalib version"));
  EXPECT_FALSE(std::filesystem::exists(tmp.path() + "/report.html"));
  EXPECT_EQ(Stcalib("report").exit_code, 2);
}

}  // namespace
}  // namespace stcalib
