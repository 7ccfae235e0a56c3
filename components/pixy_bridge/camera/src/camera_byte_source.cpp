#include "pixyslam/camera/camera_byte_source.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "pixyslam/config/parameters_yaml.h"
#include "pixyslam/pixy/pixy_block_parser.h"

namespace pixyslam::camera {
namespace {

constexpr std::size_t kReadChunk = 64 * 1024;

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

void read_range(config::YamlReader& r, const std::string& key, int& min, int& max, int limit) {
  min = static_cast<int>(r.integer(key + "_min", 0, limit, min));
  max = static_cast<int>(r.integer(key + "_max", 0, limit, max));
}

}  // namespace

const parameters::Table<CameraSourceOptions>& camera_source_parameters() {
  using O = CameraSourceOptions;
  namespace P = parameters;
  static const P::Table<O> table = {
      P::required(P::text<O>("input", "a /dev/videoN camera, a y4m file or FIFO, or a video file",
                             [](O& o) -> std::string& { return o.input; },
                             [](const std::string& v) {
                               if (v.empty()) throw std::invalid_argument("empty (a camera, a y4m file or FIFO, or a video file)");
                             })),
      P::real<O>("file_fps", 0.1, 1000.0, "Hz", "frames per second read from a file (a FIFO or camera sets its own pace)",
                 [](O& o) -> double& { return o.file_fps; }),
      P::integer<O, int>("min_blob_area_px", 1, 100000, "px", "smaller blobs of a colour are noise",
                         [](O& o) -> int& { return o.detector.min_blob_area_px; }),
      P::integer<O, int>("max_gap_px", 0, 100, "px", "most rows between the two bands of a code",
                         [](O& o) -> int& { return o.detector.max_gap_px; }),
      P::real<O>("min_overlap", 0.0, 1.0, "", "horizontal overlap of the bands, fraction of the narrower",
                 [](O& o) -> double& { return o.detector.min_overlap; }),
      P::real<O>("horizon_row_fraction", -1.0, 1.0, "", "a code's centre lies on this row (fraction of the height; < 0: off)",
                 [](O& o) -> double& { return o.detector.horizon_row_fraction; }),
      P::real<O>("max_horizon_offset", 0.0, 10.0, "", "... within this many code heights",
                 [](O& o) -> double& { return o.detector.max_horizon_offset; }),
  };
  return table;
}

void validate(const CameraSourceOptions& o) { parameters::check_ranges(o, camera_source_parameters(), "camera"); }

CameraSourceOptions read_camera_source_options(config::YamlReader& camera, int image_width_px, int image_height_px) {
  CameraSourceOptions o;
  o.image_width_px = image_width_px;
  o.image_height_px = image_height_px;
  config::read_parameters(camera, camera_source_parameters(), o);
  DetectorOptions& d = o.detector;
  if (camera.has("signatures")) {
    config::YamlReader sigs = camera.child("signatures");
    for (int k = 1; k <= 7; ++k) {
      const std::string key = std::to_string(k);
      if (!sigs.has(key)) continue;
      config::YamlReader s = sigs.child(key);
      HsvRange& h = d.signatures[static_cast<std::size_t>(k - 1)];
      read_range(s, "h", h.h_min, h.h_max, 179);
      read_range(s, "s", h.s_min, h.s_max, 255);
      read_range(s, "v", h.v_min, h.v_max, 255);
      s.finish();
    }
    sigs.finish();
  }
  camera.finish();
  return o;
}

std::string to_yaml(const CameraSourceOptions& o) {
  std::ostringstream os;
  const DetectorOptions& d = o.detector;
  os << parameters::to_yaml(o, camera_source_parameters(), "camera") << "  signatures:\n";
  for (std::size_t k = 0; k < d.signatures.size(); ++k) {
    const HsvRange& h = d.signatures[k];
    if (h.s_min > h.s_max) continue;
    os << "    \"" << k + 1 << "\": {h_min: " << h.h_min << ", h_max: " << h.h_max << ", s_min: " << h.s_min
       << ", s_max: " << h.s_max << ", v_min: " << h.v_min << ", v_max: " << h.v_max << "}\n";
  }
  return os.str();
}

CameraByteSource::CameraByteSource(CameraSourceOptions options, bridge::LogFunction log)
    : options_(std::move(options)), log_(std::move(log)), y4m_([this](const std::string& m) { log_(m); }) {}

CameraByteSource::~CameraByteSource() { close(); }

void CameraByteSource::open() {
  close();
  const std::string& in = options_.input;
  struct stat st {};
  const bool exists = ::stat(in.c_str(), &st) == 0;
  if (in.rfind("/dev/video", 0) == 0) {
    kind_ = Kind::kVideo;
    is_file_ = false;
    capture_ = std::make_unique<cv::VideoCapture>(in, cv::CAP_V4L2);
  } else if (exists && (S_ISFIFO(st.st_mode) || ends_with(in, ".y4m"))) {
    kind_ = Kind::kY4m;
    is_file_ = S_ISREG(st.st_mode);
    fd_ = ::open(in.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) throw std::runtime_error("cannot open '" + in + "': " + std::strerror(errno));
    y4m_.reset();
  } else if (exists) {
    kind_ = Kind::kVideo;
    is_file_ = true;
    capture_ = std::make_unique<cv::VideoCapture>(in);
  } else {
    throw std::runtime_error("cannot open '" + in + "': no such file, FIFO or camera");
  }
  if (capture_ && !capture_->isOpened()) {
    capture_.reset();
    throw std::runtime_error("cannot open '" + in + "' as a " + (is_file_ ? "video file" : "V4L2 camera"));
  }
  open_ = true;
  ended_ = false;
  pending_.clear();
  y4m_frames_.clear();
  next_due_ = std::chrono::steady_clock::now();
}

void CameraByteSource::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  capture_.reset();
  open_ = false;
}

void CameraByteSource::deliver(const cv::Mat& frame) {
  ++frames_;
  cv::Mat image = frame;
  if (image.cols != options_.image_width_px || image.rows != options_.image_height_px) {
    if (!size_logged_) {
      log_("camera: frames are " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
           ", resized to the camera model's " + std::to_string(options_.image_width_px) + "x" +
           std::to_string(options_.image_height_px));
      size_logged_ = true;
    }
    cv::resize(frame, image, cv::Size(options_.image_width_px, options_.image_height_px), 0, 0, cv::INTER_AREA);
  }
  const std::vector<std::uint8_t> bytes = pixy::encode_frame(detect_colour_codes(image, options_.detector));
  pending_.insert(pending_.end(), bytes.begin(), bytes.end());
}

serial::ReadResult CameraByteSource::end_of_file() {
  if (!ended_) log_("camera: end of '" + options_.input + "' after " + std::to_string(frames_) + " frames");
  ended_ = true;
  return {serial::ReadStatus::kTimeout, 0};
}

bool CameraByteSource::file_frame_due(std::chrono::milliseconds timeout) {
  if (!is_file_) return true;  // a camera or FIFO sets its own pace
  // A file plays at file_fps, like a camera.
  const auto now = std::chrono::steady_clock::now();
  if (now < next_due_) {
    std::this_thread::sleep_for(std::min<std::chrono::steady_clock::duration>(next_due_ - now, timeout));
    if (std::chrono::steady_clock::now() < next_due_) return false;
  }
  next_due_ += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / options_.file_fps));
  return true;
}

serial::ReadResult CameraByteSource::next_y4m(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (y4m_frames_.empty()) {
    if (ended_) return end_of_file();
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd p{fd_, POLLIN, 0};
    const int r = ::poll(&p, 1, static_cast<int>(std::max<long>(0, left.count())));
    if (r < 0 && errno != EINTR) throw std::runtime_error("poll '" + options_.input + "': " + std::strerror(errno));
    if (r <= 0) return {serial::ReadStatus::kTimeout, 0};
    std::uint8_t chunk[kReadChunk];
    const ssize_t n = ::read(fd_, chunk, sizeof chunk);
    if (n < 0) {
      if (errno == EAGAIN || errno == EINTR) continue;
      throw std::runtime_error("read '" + options_.input + "': " + std::strerror(errno));
    }
    if (n == 0) {
      if (is_file_) return end_of_file();
      return {serial::ReadStatus::kHangup, 0};  // the FIFO's writer left
    }
    y4m_.feed(chunk, static_cast<std::size_t>(n), [this](cv::Mat&& f) { y4m_frames_.push_back(std::move(f)); });
  }
  if (!file_frame_due(timeout)) return {serial::ReadStatus::kTimeout, 0};
  deliver(y4m_frames_.front());
  y4m_frames_.pop_front();
  return {serial::ReadStatus::kData, 0};
}

serial::ReadResult CameraByteSource::next_video(std::chrono::milliseconds timeout) {
  if (ended_) return end_of_file();
  if (!file_frame_due(timeout)) return {serial::ReadStatus::kTimeout, 0};
  cv::Mat frame;
  if (!capture_->read(frame) || frame.empty()) {
    if (is_file_) return end_of_file();
    return {serial::ReadStatus::kHangup, 0};  // the camera stopped delivering (unplugged)
  }
  if (frame.type() != CV_8UC3) {
    cv::Mat bgr;
    if (frame.channels() == 1) cv::cvtColor(frame, bgr, cv::COLOR_GRAY2BGR);
    else if (frame.channels() == 4) cv::cvtColor(frame, bgr, cv::COLOR_BGRA2BGR);
    else throw std::runtime_error("'" + options_.input + "' delivers frames of an unsupported pixel type");
    frame = bgr;
  }
  deliver(frame);
  return {serial::ReadStatus::kData, 0};
}

serial::ReadResult CameraByteSource::read_some(std::uint8_t* buffer, std::size_t max,
                                               std::chrono::milliseconds timeout) {
  if (!open_) throw std::runtime_error("read from '" + options_.input + "' while closed");
  if (pending_.empty()) {
    const serial::ReadResult r = kind_ == Kind::kY4m ? next_y4m(timeout) : next_video(timeout);
    if (r.status != serial::ReadStatus::kData) return r;
  }
  const std::size_t n = std::min(max, pending_.size());
  std::memcpy(buffer, pending_.data(), n);
  pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(n));
  return {serial::ReadStatus::kData, n};
}

}  // namespace pixyslam::camera
