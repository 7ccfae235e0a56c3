#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/mrclam/mrclam_dataset.h"

namespace pixyslam::mrclam {
namespace {

// Writes a small synthetic MRCLAM folder (robot 1) into a unique temp dir.
class MrclamTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device rd;
    dir_ = std::filesystem::temp_directory_path() /
           ("pixyslam_test_mrclam_" + std::to_string(rd()) + "_" + std::to_string(rd()));
    std::filesystem::create_directories(dir_);

    write("Barcodes.dat", crlf(header("Barcode") +
                               "  1 \t   5 \n  2 \t  14 \n  3 \t  41 \n  4 \t  32 \n  5 \t  23 \n"
                               "  6 \t  63 \n  7 \t  81 \n  8 \t   7 \n 11 \t  27 \n 17 \t  16 \n"));
    write("Landmark_Groundtruth.dat", crlf(header("Landmark Groundtruth") +
                                           "  6 \t 0.5 \t -4.25 \t 0.0001 \t 0.0002 \n"
                                           "  7 \t 0.75 \t -4.5 \t 0.0001 \t 0.0002 \n"
                                           "  8 \t 1.0 \t 2.0 \t 0.0001 \t 0.0002 \n"
                                           " 11 \t 3.0 \t 1.0 \t 0.0001 \t 0.0002 \n"
                                           " 17 \t -2.0 \t 0.5 \t 0.0001 \t 0.0002 \n"));
    // Odometry with one row out of order; CRLF line ends.
    write("Robot1_Odometry.dat", crlf(header("Odometry") +
                                      "1248444187.156 \t  0.086 \t -0.398 \n"
                                      "1248444187.256 \t  0.100 \t  0.000 \n"
                                      "1248444187.206 \t  0.050 \t  0.125 \n"));
    // Measurements (LF, with a blank line). Barcode -> subject:
    //   63 -> 6, 81 -> 7, 27 -> 11 (landmarks); 14 -> 2, 41 -> 3 (robots);
    //   34, 52 (in no Barcodes row: spurious).
    write("Robot1_Measurement.dat", header("Measurement") +
                                        "1248444189.599 \t  63 \t  3.787 \t -0.257 \n"  // line 5
                                        "1248444189.599 \t  14 \t  2.000 \t  0.100 \n"
                                        "1248444189.599 \t  81 \t  6.758 \t -0.005 \n"
                                        "1248444190.000 \t  41 \t  1.500 \t  0.300 \n"  // robot only: no frame
                                        "\n"
                                        "1248444190.500 \t  34 \t  2.500 \t  0.200 \n"
                                        "1248444190.500 \t  27 \t  4.000 \t  0.400 \n"
                                        "1248444191.000 \t  52 \t  1.000 \t  0.000 \n");  // spurious only
    write("Robot1_Groundtruth.dat", crlf(header("Robot Groundtruth") +
                                         "1248444175.103 \t 1.41277290 \t -3.89107760 \t 2.26960000 \n"
                                         "1248444175.115 \t 1.41278500 \t -3.89107880 \t 2.26960000 \n"));
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }

  static std::string header(const std::string& kind) {
    return "# UTIAS Multi-Robot Cooperative Localization and Mapping Dataset\n"
           "# produced by test\n"
           "# " + kind + " Data Format:\n"
           "# columns\n";
  }
  static std::string crlf(const std::string& text) {
    std::string out;
    for (const char c : text) {
      if (c == '\n') out += '\r';
      out += c;
    }
    return out;
  }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  std::string dir() const { return dir_.string(); }

  // Loads robot 1 expecting a std::runtime_error and returns its message.
  std::string load_error() const {
    try {
      load_robot(dir(), 1);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    ADD_FAILURE() << "expected std::runtime_error";
    return {};
  }

  std::filesystem::path dir_;
};

TEST_F(MrclamTest, ReadsCrlfFilesAndSortsOdometry) {
  const RobotData d = load_robot(dir(), 1);
  EXPECT_EQ(d.robot, 1);
  ASSERT_EQ(d.odometry.size(), 3u);
  EXPECT_DOUBLE_EQ(d.odometry[0].t_s, 1248444187.156);
  EXPECT_DOUBLE_EQ(d.odometry[1].t_s, 1248444187.206);
  EXPECT_DOUBLE_EQ(d.odometry[1].v_mps, 0.05);
  EXPECT_DOUBLE_EQ(d.odometry[1].w_radps, 0.125);
  EXPECT_DOUBLE_EQ(d.odometry[2].t_s, 1248444187.256);

  ASSERT_EQ(d.groundtruth.size(), 2u);
  EXPECT_DOUBLE_EQ(d.groundtruth[0].t_s, 1248444175.103);
  EXPECT_DOUBLE_EQ(d.groundtruth[0].x_m, 1.4127729);
  EXPECT_DOUBLE_EQ(d.groundtruth[0].y_m, -3.8910776);
  EXPECT_DOUBLE_EQ(d.groundtruth[0].theta_rad, 2.2696);

  ASSERT_EQ(d.landmarks.size(), 5u);
  EXPECT_EQ(d.landmarks[0].id, 6);
  EXPECT_DOUBLE_EQ(d.landmarks[0].x_m, 0.5);
  EXPECT_DOUBLE_EQ(d.landmarks[0].y_m, -4.25);
  EXPECT_EQ(d.landmark_file, "Landmark_Groundtruth.dat");
}

TEST_F(MrclamTest, MapsBarcodesDropsRobotsAndSpuriousAndGroupsFrames) {
  const RobotData d = load_robot(dir(), 1);
  EXPECT_EQ(d.counts.measurement_rows, 7u);
  EXPECT_EQ(d.counts.robot_rows, 2u);
  EXPECT_EQ(d.counts.unknown_barcode_rows, 2u);
  EXPECT_EQ(d.counts.landmark_rows, 3u);

  ASSERT_EQ(d.frames.size(), 2u);
  EXPECT_DOUBLE_EQ(d.frames[0].t_s, 1248444189.599);
  ASSERT_EQ(d.frames[0].detections.size(), 2u);
  EXPECT_EQ(d.frames[0].detections[0].subject, 6);
  EXPECT_DOUBLE_EQ(d.frames[0].detections[0].range_m, 3.787);
  EXPECT_DOUBLE_EQ(d.frames[0].detections[0].bearing_rad, -0.257);
  EXPECT_EQ(d.frames[0].detections[1].subject, 7);

  EXPECT_DOUBLE_EQ(d.frames[1].t_s, 1248444190.5);
  ASSERT_EQ(d.frames[1].detections.size(), 1u);
  EXPECT_EQ(d.frames[1].detections[0].subject, 11);
  EXPECT_DOUBLE_EQ(d.frames[1].detections[0].range_m, 4.0);
}

// A data set converted from another robot may number its landmarks from 1: a
// subject the landmark file lists is a landmark, even among the robots' 1-5.
TEST_F(MrclamTest, ASubjectTheLandmarkFileListsIsALandmarkEvenBelowSix) {
  write("Landmark_Groundtruth.dat", header("Landmark Groundtruth") +
                                        "  3 \t 2.0 \t 1.0 \t 0.0001 \t 0.0002 \n"
                                        "  6 \t 0.5 \t -4.25 \t 0.0001 \t 0.0002 \n");
  const RobotData d = load_robot(dir(), 1);
  EXPECT_EQ(d.counts.robot_rows, 1u);     // subject 2 (barcode 14) is still a robot
  EXPECT_EQ(d.counts.landmark_rows, 4u);  // subject 3 (barcode 41) joined the landmarks
  ASSERT_EQ(d.frames.size(), 3u);
  EXPECT_DOUBLE_EQ(d.frames[1].t_s, 1248444190.0);
  ASSERT_EQ(d.frames[1].detections.size(), 1u);
  EXPECT_EQ(d.frames[1].detections[0].subject, 3);
  EXPECT_DOUBLE_EQ(d.frames[1].detections[0].range_m, 1.5);
}

TEST_F(MrclamTest, MeasurementsOutOfOrderAreSortedBeforeGrouping) {
  write("Robot1_Measurement.dat", header("Measurement") +
                                      "20.0 63 1.0 0.0\n"
                                      "10.0 81 2.0 0.0\n"
                                      "20.0 27 3.0 0.0\n");
  const RobotData d = load_robot(dir(), 1);
  ASSERT_EQ(d.frames.size(), 2u);
  EXPECT_DOUBLE_EQ(d.frames[0].t_s, 10.0);
  ASSERT_EQ(d.frames[1].detections.size(), 2u);
  EXPECT_EQ(d.frames[1].detections[0].subject, 6);  // file order kept within a frame
  EXPECT_EQ(d.frames[1].detections[1].subject, 11);
}

TEST_F(MrclamTest, MissingGroundtruthGivesEmptyTrajectory) {
  std::filesystem::remove(dir_ / "Robot1_Groundtruth.dat");
  const RobotData d = load_robot(dir(), 1);
  EXPECT_TRUE(d.groundtruth.empty());
  EXPECT_EQ(d.odometry.size(), 3u);
  EXPECT_EQ(d.frames.size(), 2u);
}

// A recording without surveyed landmarks still loads: no landmark truth, the
// detections all kept (subjects above 5), robots (1-5) dropped as before.
TEST_F(MrclamTest, MissingLandmarkFileGivesNoLandmarkTruth) {
  std::filesystem::remove(dir_ / "Landmark_Groundtruth.dat");
  const RobotData d = load_robot(dir(), 1);
  EXPECT_TRUE(d.landmarks.empty());
  EXPECT_EQ(d.landmark_file, "");
  EXPECT_EQ(d.counts.landmark_rows, 3u);
  EXPECT_EQ(d.counts.robot_rows, 2u);
  EXPECT_EQ(d.frames.size(), 2u);
}

TEST_F(MrclamTest, PrefersFixedLandmarkFile) {
  write("Landmark_Groundtruth_fixed_11_17.dat", header("Landmark Groundtruth") +
                                                    " 11 \t -2.0 \t 0.5 \t 0.0001 \t 0.0002 \n"
                                                    " 17 \t 3.0 \t 1.0 \t 0.0001 \t 0.0002 \n");
  const RobotData d = load_robot(dir(), 1);
  EXPECT_EQ(d.landmark_file, "Landmark_Groundtruth_fixed_11_17.dat");
  ASSERT_EQ(d.landmarks.size(), 2u);
  EXPECT_EQ(d.landmarks[0].id, 11);
  EXPECT_DOUBLE_EQ(d.landmarks[0].x_m, -2.0);
  EXPECT_EQ(d.landmarks[1].id, 17);
  EXPECT_DOUBLE_EQ(d.landmarks[1].x_m, 3.0);
}

TEST_F(MrclamTest, WrongColumnCountNamesFileAndLine) {
  write("Robot1_Measurement.dat", header("Measurement") +
                                      "1.0 63 3.0 0.1\n"
                                      "1.0 81 3.0 0.1\n"
                                      "2.0 27 3.0\n");  // line 7
  const std::string msg = load_error();
  EXPECT_NE(msg.find("Robot1_Measurement.dat:7"), std::string::npos) << msg;
  EXPECT_NE(msg.find("expected 4 columns, found 3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("2.0 27 3.0"), std::string::npos) << msg;
}

TEST_F(MrclamTest, NonNumberNamesFileLineAndText) {
  write("Robot1_Odometry.dat", crlf(header("Odometry") + "1.0 0.1 0.2\n\n1.1 0.1x 0.2\n"));  // line 7
  const std::string msg = load_error();
  EXPECT_NE(msg.find("Robot1_Odometry.dat:7"), std::string::npos) << msg;
  EXPECT_NE(msg.find("0.1x"), std::string::npos) << msg;
  EXPECT_EQ(msg.find('\r'), std::string::npos) << "CR leaked into the message";
}

TEST_F(MrclamTest, NonFiniteAndNonIntegerBarcodeRejected) {
  write("Robot1_Odometry.dat", header("Odometry") + "1.0 nan 0.2\n");
  EXPECT_NE(load_error().find("Robot1_Odometry.dat:5"), std::string::npos);

  write("Robot1_Odometry.dat", header("Odometry") + "1.0 0.1 0.2\n");
  write("Robot1_Measurement.dat", header("Measurement") + "1.0 63.5 3.0 0.1\n");
  EXPECT_NE(load_error().find("Robot1_Measurement.dat:5"), std::string::npos);
}

TEST_F(MrclamTest, MissingRequiredFileIsNamed) {
  std::filesystem::remove(dir_ / "Barcodes.dat");
  EXPECT_NE(load_error().find("Barcodes.dat"), std::string::npos);
}

TEST_F(MrclamTest, MissingRobotFileIsNamed) {
  // Robot 2 has no files at all in this folder.
  try {
    load_robot(dir(), 2);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("Robot2_Odometry.dat"), std::string::npos) << e.what();
  }
}

TEST_F(MrclamTest, RobotNumberOutOfRangeThrows) {
  EXPECT_THROW(load_robot(dir(), 0), std::runtime_error);
  EXPECT_THROW(load_robot(dir(), 6), std::runtime_error);
  EXPECT_THROW(load_robot((dir_ / "absent").string(), 1), std::runtime_error);
}

TEST_F(MrclamTest, WrittenRobotReadsBackExactly) {
  RobotData d;
  d.robot = 3;
  d.odometry = {{0.1, 0.2, -0.3}, {0.15, 1.0 / 3.0, 1e-9}};
  d.frames = {{0.12, {{6, 2.5, 0.25}, {9, 1.0 / 7.0, -0.5}}}, {0.2, {{6, 2.25, 0.3}}}};
  d.groundtruth = {{0.1, 1.0, -2.0, 3.0}, {0.2, 1.1, -2.1, -3.1}};
  d.landmarks = {{6, 0.5, -0.25}, {9, 4.0 / 3.0, 7.0}};
  const std::string out = (dir_ / "written").string();
  write_robot(out, d);
  const RobotData r = load_robot(out, 3);
  ASSERT_EQ(r.odometry.size(), 2u);
  EXPECT_EQ(r.odometry[1].v_mps, 1.0 / 3.0);
  EXPECT_EQ(r.odometry[1].w_radps, 1e-9);
  ASSERT_EQ(r.frames.size(), 2u);
  ASSERT_EQ(r.frames[0].detections.size(), 2u);
  EXPECT_EQ(r.frames[0].detections[1].subject, 9);
  EXPECT_EQ(r.frames[0].detections[1].range_m, 1.0 / 7.0);
  EXPECT_EQ(r.frames[1].t_s, 0.2);
  ASSERT_EQ(r.groundtruth.size(), 2u);
  EXPECT_EQ(r.groundtruth[1].theta_rad, -3.1);
  ASSERT_EQ(r.landmarks.size(), 2u);
  EXPECT_EQ(r.landmarks[1].x_m, 4.0 / 3.0);
  EXPECT_EQ(r.counts.landmark_rows, 3u);
  EXPECT_EQ(r.counts.unknown_barcode_rows + r.counts.robot_rows, 0u);
  // Robot 1 of the same folder was not written.
  EXPECT_THROW(load_robot(out, 1), std::runtime_error);
}

TEST_F(MrclamTest, WritingRefusesRobotNumbersAsLandmarks) {
  RobotData d;
  d.robot = 1;
  d.landmarks = {{5, 0.0, 0.0}};
  try {
    write_robot((dir_ / "bad").string(), d);
    ADD_FAILURE() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("landmark subject 5"), std::string::npos) << e.what();
  }
  d.landmarks = {{6, 0.0, 0.0}};
  d.frames = {{1.0, {{2, 1.0, 0.0}}}};
  EXPECT_THROW(write_robot((dir_ / "bad").string(), d), std::runtime_error);
  d.robot = 6;
  d.frames.clear();
  EXPECT_THROW(write_robot((dir_ / "bad").string(), d), std::runtime_error);
}

}  // namespace
}  // namespace pixyslam::mrclam
