// map_view live against real DDS writers on a private domain: the process
// starts without a display, draws what it receives (MapState, OptimisedMap)
// into map_latest.png, and ends with status 0 on SIGINT after a last snapshot.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pixyslam/dds/endpoints.h"

namespace pixyslam {
namespace {

namespace fs = std::filesystem;

TEST(MapViewLive, DrawsReceivedMapStatesAndStopsOnSigint) {
  const int domain = 140 + static_cast<int>(getpid() % 50);
  const fs::path out = fs::temp_directory_path() / ("pixyslam_map_view_live_" + std::to_string(getpid()));
  fs::remove_all(out);
  const std::string domain_text = std::to_string(domain);
  const std::string out_text = out.string();

  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    unsetenv("DISPLAY");
    unsetenv("WAYLAND_DISPLAY");
    execl(PIXYSLAM_MAP_VIEW_EXE, "map_view", "live", "--domain", domain_text.c_str(), "--out-dir", out_text.c_str(),
          "--period", "0.2", static_cast<char*>(nullptr));
    _exit(127);
  }

  dds::DdsOptions options;
  options.domain_id = domain;
  options.profiles_file = PIXYSLAM_CONFIG_DIR "/dds/profiles.xml";
  {
    dds::Participant participant(options, "test_map_view_live");
    dds::Writer<msg::MapState> writer(participant);
    dds::Writer<msg::OptimisedMap> optimised_writer(participant);
    ASSERT_TRUE(writer.wait_for_readers(1, std::chrono::seconds(20)));
    ASSERT_TRUE(optimised_writer.wait_for_readers(1, std::chrono::seconds(20)));
    for (int i = 1; i <= 20; ++i) {
      msg::MapState m;
      m.header().stamp_ns(1'000'000'000ULL * static_cast<std::uint64_t>(i));
      m.mean_pose().x_m(0.1 * i);
      m.particle_count(50);
      m.effective_sample_size(42.0);
      msg::LandmarkEstimate l;
      l.landmark_id(5);
      l.x_m(1.0);
      l.y_m(1.0);
      l.cov_xx_m2(0.01);
      l.cov_yy_m2(0.01);
      m.landmarks().push_back(l);
      ASSERT_TRUE(writer.publish(m));
      // MapState is keep-last 1: a reader sees the latest, not every state of a burst.
      std::this_thread::sleep_for(std::chrono::milliseconds(40));
    }
    // The optimiser's solution: keyframes along y = -0.5, a landmark at (1.5, 1).
    msg::OptimisedMap optimised;
    optimised.header().stamp_ns(20'000'000'000ULL);
    for (int i = 0; i <= 20; ++i) {
      msg::OptimisedKeyframe k;
      k.stamp_ns(1'000'000'000ULL * static_cast<std::uint64_t>(i));
      k.pose().x_m(0.1 * i);
      k.pose().y_m(-0.5);
      optimised.keyframes().push_back(k);
    }
    optimised.keyframe_count(21);
    msg::OptimisedLandmark l;
    l.landmark_id(5);
    l.x_m(1.5);
    l.y_m(1.0);
    l.cov_xx_m2(0.01);
    l.cov_yy_m2(0.01);
    optimised.landmarks().push_back(l);
    ASSERT_TRUE(optimised_writer.publish(optimised));
    EXPECT_TRUE(writer.wait_for_acknowledgments(std::chrono::seconds(10)));
    EXPECT_TRUE(optimised_writer.wait_for_acknowledgments(std::chrono::seconds(10)));
    std::this_thread::sleep_for(std::chrono::milliseconds(800));  // > two snapshot periods
  }
  kill(child, SIGINT);
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);

  const cv::Mat image = cv::imread((out / "map_latest.png").string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 800);
  EXPECT_EQ(image.rows, 800);
  // The landmark (red) and the trajectory (blue) are in it.
  cv::Mat red, blue;
  cv::inRange(image, cv::Scalar(0, 0, 190), cv::Scalar(40, 40, 230), red);
  cv::inRange(image, cv::Scalar(180, 70, 0), cv::Scalar(220, 110, 40), blue);
  EXPECT_GT(cv::countNonZero(red), 20);
  EXPECT_GT(cv::countNonZero(blue), 100);
  // So is the optimised solution (orange, the default colour (240, 140, 0)).
  cv::Mat orange;
  cv::inRange(image, cv::Scalar(0, 110, 210), cv::Scalar(40, 170, 255), orange);
  EXPECT_GT(cv::countNonZero(orange), 100);
  fs::remove_all(out);
}

}  // namespace
}  // namespace pixyslam
