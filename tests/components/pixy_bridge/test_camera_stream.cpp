// The camera backend's input side: the YUV4MPEG2 stream (round trip, any
// chunking, malformed bytes skipped and reported with their offset) and the
// software Pixy (CameraByteSource) turning a y4m file of rendered poles into
// the Pixy's UART block stream.
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include <gtest/gtest.h>

#include "pixyslam/camera/camera_byte_source.h"
#include "pixyslam/sim/synthetic_camera.h"
#include "pixyslam/camera/y4m_stream.h"
#include "pixyslam/config/yaml_reader.h"
#include "pixyslam/pixy/pixy_block_parser.h"
#include "pixyslam/pixy/pixy_options.h"

namespace pixyslam::camera {
namespace {

using sim::SyntheticPole;
using sim::SyntheticCameraOptions;
using sim::render_camera_image;

cv::Mat random_image(int w, int h, std::uint64_t seed) {
  cv::Mat m(h, w, CV_8UC3);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  return m;
}

std::vector<std::uint8_t> bytes_of(const std::string& s) { return {s.begin(), s.end()}; }

std::vector<cv::Mat> parse_in_chunks(const std::vector<std::uint8_t>& stream, std::uint64_t seed, Y4mParser& parser) {
  std::vector<cv::Mat> frames;
  std::mt19937_64 rng(seed);
  for (std::size_t i = 0; i < stream.size();) {
    const std::size_t n = std::min<std::size_t>(1 + rng() % 5000, stream.size() - i);
    parser.feed(stream.data() + i, n, [&](cv::Mat&& f) { frames.push_back(std::move(f)); });
    i += n;
  }
  return frames;
}

TEST(Y4mStream, FramesSurviveTheRoundTripWhateverTheChunks) {
  std::vector<std::uint8_t> stream = bytes_of(y4m_header(37, 21, 10, 1));
  std::vector<cv::Mat> sent;
  for (int k = 0; k < 3; ++k) {
    sent.push_back(random_image(37, 21, 10 + k));
    const std::vector<std::uint8_t> f = encode_y4m_frame(sent.back());
    stream.insert(stream.end(), f.begin(), f.end());
  }
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    Y4mParser parser;
    const std::vector<cv::Mat> got = parse_in_chunks(stream, seed, parser);
    ASSERT_EQ(got.size(), sent.size());
    for (std::size_t k = 0; k < got.size(); ++k) {
      ASSERT_EQ(got[k].size(), sent[k].size());
      // YCrCb is 8-bit: a colour may come back a few levels off, never more.
      EXPECT_LE(cv::norm(got[k], sent[k], cv::NORM_INF), 3.0) << "frame " << k;
    }
    EXPECT_EQ(parser.counters().frames, 3u);
    EXPECT_EQ(parser.counters().bytes_skipped, 0u);
    EXPECT_EQ(parser.counters().bytes_in, stream.size());
  }
}

TEST(Y4mStream, GarbageIsSkippedCountedAndReportedWithItsOffset) {
  const std::string header = y4m_header(8, 4, 10, 1);
  const cv::Mat image = random_image(8, 4, 3);
  const std::vector<std::uint8_t> frame = encode_y4m_frame(image);
  std::vector<std::uint8_t> stream = bytes_of("junk!" + header);  // 5 bytes before the header
  stream.insert(stream.end(), frame.begin(), frame.end());
  const std::string noise = "xxFRAMxx";  // between frames: 8 bytes, one a near-miss marker
  stream.insert(stream.end(), noise.begin(), noise.end());
  stream.insert(stream.end(), frame.begin(), frame.end());
  std::vector<std::string> errors;
  Y4mParser parser([&](const std::string& e) { errors.push_back(e); });
  const std::vector<cv::Mat> got = parse_in_chunks(stream, 9, parser);
  EXPECT_EQ(got.size(), 2u);
  EXPECT_EQ(parser.counters().bytes_skipped, 5u + 8u);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_NE(errors[0].find("byte offset 0"), std::string::npos) << errors[0];
  const std::size_t second = 5 + header.size() + frame.size();
  EXPECT_NE(errors[1].find("byte offset " + std::to_string(second)), std::string::npos) << errors[1];
}

TEST(Y4mStream, RejectsUnreadableHeadersAndReads420AndMono) {
  std::vector<std::string> errors;
  Y4mParser parser([&](const std::string& e) { errors.push_back(e); });
  std::vector<cv::Mat> got;
  const auto feed = [&](const std::vector<std::uint8_t>& b) {
    parser.feed(b.data(), b.size(), [&](cv::Mat&& f) { got.push_back(std::move(f)); });
  };
  feed(bytes_of("YUV4MPEG2 W0 H4 C444\n"));
  feed(bytes_of("YUV4MPEG2 W4 H4 C422\n"));
  EXPECT_EQ(parser.counters().bad_headers, 2u);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_NE(errors[1].find("C422"), std::string::npos) << errors[1];
  // 4:2:0, 3 x 3: chroma 2 x 2. A mid-grey frame with neutral chroma is grey.
  std::vector<std::uint8_t> s = bytes_of("YUV4MPEG2 W3 H3 F10:1 C420jpeg\nFRAME\n");
  s.insert(s.end(), 9, 128);
  s.insert(s.end(), 8, 128);
  feed(s);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].size(), cv::Size(3, 3));
  EXPECT_LE(cv::norm(got[0], cv::Mat(3, 3, CV_8UC3, cv::Scalar(128, 128, 128)), cv::NORM_INF), 1.0);
  s = bytes_of("YUV4MPEG2 W2 H2 Cmono\nFRAME\n");
  s.insert(s.end(), {10, 20, 30, 40});
  feed(s);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[1].at<cv::Vec3b>(1, 1), cv::Vec3b(40, 40, 40));
  EXPECT_EQ(parser.counters().headers, 2u);
}

// A y4m file of the synthetic camera's images, played by the software Pixy:
// the bytes it delivers parse as Pixy frames, one per image, with the pole's
// colour code at the column the renderer drew it.
TEST(CameraByteSource, PlaysAY4mFileAsThePixyBlockStream) {
  config::YamlReader root = config::YamlReader::from_file(std::string(PIXYSLAM_CONFIG_DIR) + "/pixy_bridge.yaml");
  config::YamlReader pixy_yaml = root.child("pixy");
  const pixy::PixyOptions pixy = pixy::read_pixy_options(pixy_yaml);
  SyntheticCameraOptions camera;
  camera.camera = pixy.camera;
  std::mt19937_64 rng(3);
  char path[] = "/tmp/pixyslam_camera_test_XXXXXX.y4m";
  const int fd = ::mkstemps(path, 4);
  ASSERT_GE(fd, 0);
  ::close(fd);
  {
    std::ofstream out(path, std::ios::binary);
    out << y4m_header(pixy.camera.image_width_px, pixy.camera.image_height_px, 10, 1);
    for (int k = 0; k < 4; ++k) {
      const SyntheticPole pole{1, 1.0, 0.1 * (k - 1), 1, 2};  // tags 1 over 2: landmark 1
      const std::vector<std::uint8_t> f =
          encode_y4m_frame(render_camera_image(slam::Pose2::Zero(), {pole}, camera, default_detector_options(), rng));
      out.write(reinterpret_cast<const char*>(f.data()), static_cast<std::streamsize>(f.size()));
    }
  }
  CameraSourceOptions options;
  options.input = path;
  options.file_fps = 200.0;
  std::vector<std::string> log;
  CameraByteSource source(options, [&](const std::string& line) { log.push_back(line); });
  source.open();
  pixy::PixyBlockParser parser;
  std::vector<pixy::PixyFrame> frames;
  std::uint8_t buffer[256];
  for (int i = 0; i < 200 && source.frames() < 4; ++i) {
    const serial::ReadResult r = source.read_some(buffer, sizeof buffer, std::chrono::milliseconds(20));
    ASSERT_NE(r.status, serial::ReadStatus::kHangup);
    parser.feed(buffer, r.bytes, [&](pixy::PixyFrame&& f) { frames.push_back(std::move(f)); });
  }
  for (int i = 0; i < 20; ++i) {  // drain the last frame's bytes
    const serial::ReadResult r = source.read_some(buffer, sizeof buffer, std::chrono::milliseconds(5));
    parser.feed(buffer, r.bytes, [&](pixy::PixyFrame&& f) { frames.push_back(std::move(f)); });
  }
  if (std::optional<pixy::PixyFrame> last = parser.flush()) frames.push_back(std::move(*last));
  std::remove(path);
  EXPECT_EQ(source.frames(), 4u);
  ASSERT_EQ(frames.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    ASSERT_EQ(frames[k].blocks.size(), 1u) << "frame " << k;
    EXPECT_EQ(pixy.signatures.landmark_of(frames[k].blocks[0]), std::optional<int>(1));
    EXPECT_NEAR(pixy::bearing_rad(pixy.camera, frames[k].blocks[0].x), 0.1 * (k - 1), 0.02) << "frame " << k;
  }
  ASSERT_FALSE(log.empty());
  EXPECT_NE(log.back().find("end of"), std::string::npos) << log.back();
}

TEST(CameraByteSource, NamesAMissingInputWhenOpening) {
  CameraSourceOptions options;
  options.input = "/tmp/pixyslam_no_such_camera_input.y4m";
  CameraByteSource source(options, [](const std::string&) {});
  try {
    source.open();
    FAIL() << "opened a missing input";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/tmp/pixyslam_no_such_camera_input.y4m"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pixyslam::camera
