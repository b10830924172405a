// writeNpy against numpy.save's layout (numpy.lib.format, version 1.0): the bytes numpy writes
// for the same array, written out by hand.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "norm2tex/common/error.hpp"
#include "norm2tex/common/npy_file.hpp"

namespace norm2tex {
namespace {

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(NpyFile, HeaderIsNumpysForATwoChannelField) {
  // numpy.save of np.zeros((240, 320, 2), np.float32) starts with these 128 bytes.
  const std::string dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (240, 320, 2), }";
  const std::string header = npyHeader(240, 320, 2);
  ASSERT_EQ(header.size(), 128u);
  EXPECT_EQ(header.substr(0, 8), std::string("\x93NUMPY\x01\x00", 8));
  EXPECT_EQ(static_cast<unsigned char>(header[8]) + 256 * static_cast<unsigned char>(header[9]),
            118);
  EXPECT_EQ(header.substr(10, dict.size()), dict);
  EXPECT_EQ(header.substr(10 + dict.size()), std::string(128 - 11 - dict.size(), ' ') + "\n");
  // One channel: a 2-d array.
  EXPECT_NE(npyHeader(3, 4, 1).find("'shape': (3, 4), }"), std::string::npos);
  EXPECT_EQ(npyHeader(3, 4, 1).size() % 64, 0u);
}

TEST(NpyFile, ValuesFollowTheHeaderRowByRow) {
  const std::string dir = testing::TempDir() + "/norm2tex_npy_test";
  std::filesystem::create_directories(dir);
  cv::Mat2f field(2, 3);
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c) field(r, c) = cv::Vec2f(r * 10.0f + c, -1.5e-4f * (c + 1));
  // A view into a larger array (rows not contiguous) is written as its own values.
  cv::Mat2f wide(4, 5, cv::Vec2f(99.0f, 99.0f));
  field.copyTo(wide(cv::Rect(1, 1, 3, 2)));
  const std::string path = dir + "/field.npy";
  writeNpy(path, wide(cv::Rect(1, 1, 3, 2)));
  const std::string bytes = readBytes(path);
  const std::string header = npyHeader(2, 3, 2);
  ASSERT_EQ(bytes.size(), header.size() + 2 * 3 * 2 * sizeof(float));
  EXPECT_EQ(bytes.substr(0, header.size()), header);
  const float* values = reinterpret_cast<const float*>(bytes.data() + header.size());
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(values[(r * 3 + c) * 2], field(r, c)[0]);
      EXPECT_EQ(values[(r * 3 + c) * 2 + 1], field(r, c)[1]);
    }
  EXPECT_FALSE(std::filesystem::exists(path + ".partial"));
  std::filesystem::remove_all(dir);
}

TEST(NpyFile, BadInputIsNamed) {
  EXPECT_THROW(
      {
        try {
          writeNpy("/nonexistent_dir_norm2tex/x.npy", cv::Mat1f(2, 2, 0.0f));
        } catch (const Error& e) {
          EXPECT_NE(std::string(e.what()).find("/nonexistent_dir_norm2tex/x.npy"),
                    std::string::npos);
          throw;
        }
      },
      Error);
  EXPECT_THROW(writeNpy(testing::TempDir() + "/x.npy", cv::Mat1b(2, 2, uchar(0))), Error);
}

}  // namespace
}  // namespace norm2tex
