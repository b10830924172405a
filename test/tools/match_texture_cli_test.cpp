// Runs the real norm2tex_match_texture executable on frames rendered with a known beta and known
// forces: the material yaml it writes carries the fitted beta (within 10 %), the report is
// written, and bad input is a one-line error naming what is wrong (exit 1) or the usage (exit 2).
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli_runner.hpp"
#include "norm2tex/calibrate/texture_match.hpp"
#include "norm2tex/calibrate/texture_sample.hpp"
#include "norm2tex/materials/material_config.hpp"
#include "norm2tex/render/digit_shader.hpp"
#include "norm2tex/render/sensor_model.hpp"
#include "norm2tex/render/tactile_renderer.hpp"
#include "norm2tex/gel/gel_law.hpp"

namespace {
using norm2tex::test::CliRun;

constexpr double kTruthFactor = 1.5;  // the frames' fabric is 1.5x as deep as the shipped one

CliRun matchTexture(const std::string& arguments) {
  return norm2tex::test::runCommand(NORM2TEX_MATCH_TEXTURE_EXECUTABLE, arguments);
}

double yamlBeta(const std::string& path) {
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("beta_mm:", 0) == 0) return std::stod(line.substr(8));
  }
  return -1.0;
}

// The built-in DIGIT (synthetic background, its noise, no coating) in a sensor yaml; three presses of a flat
// fabric sample at 2, 5 and 12 N rendered with a known beta.
class MatchTextureCli : public norm2tex::test::CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    norm2tex::SensorModel model = norm2tex::makeDigitSensorModel();
    model.noise.on_real_background = true;
    // A gel without the shipped coating, through which the shipped weave's 0.5 mm threads show
    // (the coating holds them back under the sensor's noise: texture_match_test covers that).
    model.conformity.coating_length_mm = 0.0;
    norm2tex::saveSensorModel(model, path("sensor.yaml"));
    const cv::Mat3b background = norm2tex::makeSyntheticBackground(model);
    cv::imwrite(path("bg.png"), background);
    // The shipped fabric, as the tool finds it (config/materials/fabric.yaml of the source tree).
    norm2tex::MaterialConfig config =
        norm2tex::loadMaterialConfig(std::string(NORM2TEX_MATERIALS_DIR) + "/fabric.yaml");
    fabric_beta_ = config.beta_mm;
    const norm2tex::TextureSample sample = norm2tex::makeMaterialSample(config, 0);
    norm2tex::TactileRenderer renderer(model, background, norm2tex::BackgroundSource::kCaptured);
    renderer.setObject(norm2tex::TextureMatcher::sampleFace(sample.period_mm), sample.atlas,
                       kTruthFactor * fabric_beta_);
    const std::vector<double> forces = {2.0, 5.0, 12.0};
    std::filesystem::create_directories(path("frames"));
    for (size_t i = 0; i < forces.size(); ++i) {
      const double press_mm = norm2tex::GelLaw::taximDefault().indentation(forces[i]) * 1e3;
      const auto pose = norm2tex::TextureMatcher::samplePose(
          model, norm2tex::TextureMatchOptions().tilt_deg, press_mm);
      const std::string name = "frames/press" + std::to_string(i) + ".png";
      cv::imwrite(path(name), renderer.render(pose, 40 + i, forces[i]).image);
      frames_ += " " + path(name);
    }
    common_ = " --background " + path("bg.png") + " --sensor " + path("sensor.yaml");
  }
  double fabric_beta_ = 0.0;
  std::string frames_, common_;
};

TEST_F(MatchTextureCli, FitsBetaWithForcesAndWritesTheMaterialYamlAndReport) {
  const CliRun run = matchTexture("--material fabric --forces 2,5,12" + common_ + frames_ +
                                  " -o " + path("fabric.yaml") + " --report " +
                                  path("report.png"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("band RMS real"), std::string::npos) << run.output;
  const double beta = yamlBeta(path("fabric.yaml"));
  EXPECT_NEAR(beta / (kTruthFactor * fabric_beta_), 1.0, 0.10) << run.output;
  // The rest of the material is kept: it loads as fabric with the fitted beta.
  const norm2tex::MaterialConfig fitted = norm2tex::loadMaterialConfig(path("fabric.yaml"));
  EXPECT_EQ(fitted.name, "fabric");
  EXPECT_DOUBLE_EQ(fitted.beta_mm, beta);
  const cv::Mat report = cv::imread(path("report.png"));
  EXPECT_GT(report.rows, 400) << run.output;
}

TEST_F(MatchTextureCli, FitsBetaFromADirectoryByContactArea) {
  const CliRun run = matchTexture("--material fabric" + common_ + " " + path("frames") + " -o " +
                                  path("fabric.yaml"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("(gel law)"), std::string::npos) << run.output;
  EXPECT_NEAR(yamlBeta(path("fabric.yaml")) / (kTruthFactor * fabric_beta_), 1.0, 0.10)
      << run.output;
}

TEST_F(MatchTextureCli, ForcesFromACsvByBaseName) {
  std::ofstream csv(path("forces.csv"));
  csv << "file,force_n\r\n/elsewhere/press2.png,12\r\npress0.png,2\r\npress1.png,5\r\n";
  csv.close();
  const CliRun run = matchTexture("--material fabric --forces " + path("forces.csv") + common_ +
                                  frames_ + " -o " + path("fabric.yaml"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("12.00 N (given)"), std::string::npos) << run.output;
}

// One line naming what is wrong, exit 1 (input) or 2 (usage).
void expectFailure(const CliRun& run, int exit_code, const std::vector<std::string>& parts) {
  EXPECT_EQ(run.exit_code, exit_code) << run.output;
  for (const std::string& part : parts) {
    EXPECT_NE(run.output.find(part), std::string::npos) << "lacks '" << part << "':\n"
                                                        << run.output;
  }
  EXPECT_EQ(run.output.find("terminate"), std::string::npos) << run.output;
}

TEST_F(MatchTextureCli, BadInputIsAClearError) {
  const std::string out = " -o " + path("out.yaml");
  // A frame of another size than the background.
  cv::Mat small;
  cv::resize(cv::imread(path("frames/press0.png")), small, cv::Size(120, 160));
  cv::imwrite(path("small.png"), small);
  expectFailure(matchTexture("--material fabric" + common_ + frames_ + " " + path("small.png") +
                             out),
                1, {"small.png", "120 x 160", "240 x 320"});
  // An unreadable file.
  std::ofstream(path("broken.png")) << "not a png";
  expectFailure(matchTexture("--material fabric" + common_ + frames_ + " " + path("broken.png") +
                             out),
                1, {"broken.png"});
  // A frame without contact.
  expectFailure(matchTexture("--material fabric" + common_ + frames_ + " " + path("bg.png") + out),
                1, {"bg.png", "no contact"});
  // Too few frames.
  expectFailure(matchTexture("--material fabric" + common_ + " " + path("frames/press0.png") + out),
                1, {"at least 2 frames", "got 1"});
  // Forces: count, sign, finiteness.
  expectFailure(matchTexture("--material fabric --forces 2,5" + common_ + frames_ + out), 2,
                {"--forces gives 2 values for 3 frames"});
  expectFailure(matchTexture("--material fabric --forces 2,-5,12" + common_ + frames_ + out), 1,
                {"press1.png", "-5", "> 0 N"});
  expectFailure(matchTexture("--material fabric --forces 2,inf,12" + common_ + frames_ + out), 2,
                {"--forces", "inf"});
  // An unknown material names the valid ones.
  expectFailure(matchTexture("--material velvet" + common_ + frames_ + out), 1,
                {"velvet", "fabric", "wood"});
  // Usage mistakes.
  expectFailure(matchTexture(common_ + frames_ + out), 2, {"--material", "--normal-map"});
  expectFailure(matchTexture("--normal-map x.png" + common_ + frames_ + out), 2,
                {"--mm-per-texel"});
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
