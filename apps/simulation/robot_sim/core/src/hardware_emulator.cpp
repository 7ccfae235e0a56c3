#include "pixyslam/robot_sim/hardware_emulator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace pixyslam::robot_sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::int32_t wrap_int32(std::int64_t v) {
  const auto u = static_cast<std::uint32_t>(static_cast<std::uint64_t>(v));  // modulo 2^32
  return u <= 0x7fffffffu ? static_cast<std::int32_t>(u) : -static_cast<std::int32_t>(~u) - 1;
}

// sin(x) / x, exact near 0.
double sinc(double x) { return std::abs(x) < 1e-6 ? 1.0 - x * x / 6.0 : std::sin(x) / x; }

std::mt19937_64 seeded(std::uint64_t seed, std::uint32_t stream) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32), stream};
  return std::mt19937_64(seq);
}

std::uint16_t pixel(double v, int limit) {
  return static_cast<std::uint16_t>(std::clamp<long>(std::lround(v), 0, limit));
}

// Validates every option set; returns the world.
const sim::WorldOptions& validated(const sim::WorldOptions& world, const encoder::EncoderOptions& encoder,
                                   const pixy::CameraModel& camera, const HardwareOptions& hardware) {
  encoder::validate(encoder);
  pixy::validate(camera);
  validate(hardware);
  if (!(world.speed_mps > 0.0) || !(world.corner_radius_m > 0.0)) {
    throw std::invalid_argument("world: speed_mps and corner_radius_m must be > 0");
  }
  if (camera.image_width_px > 0xffff || camera.image_height_px > 0xffff) {
    throw std::invalid_argument("CameraModel: the image does not fit the Pixy's 16-bit block fields");
  }
  return world;
}

}  // namespace

HardwareEmulator::HardwareEmulator(const sim::WorldOptions& world, const encoder::EncoderOptions& encoder,
                                   const pixy::CameraModel& camera, const pixy::SignatureMap& signatures,
                                   const HardwareOptions& hardware)
    : world_(validated(world, encoder, camera, hardware)),
      encoder_(encoder),
      camera_(camera),
      hw_(hardware),
      path_(world),
      poles_(sim::place_poles(world)),
      wheel_rng_(seeded(hardware.seed, 1)),
      camera_rng_(seeded(hardware.seed, 2)),
      event_time_s_(-std::numeric_limits<double>::infinity()) {
  for (const auto& [signature, id] : signatures.entries()) signature_of_[id] = signature;
  metres_per_tick_ = 2.0 * kPi * encoder.wheel_radius_m / encoder.ticks_per_revolution;
  wheel_noise_scale_ = std::sqrt(hardware.arduino_rate_hz / hardware.noise_reference_rate_hz);
}

std::vector<eval::LandmarkPoint> HardwareEmulator::landmarks() const {
  std::vector<eval::LandmarkPoint> out;
  out.reserve(poles_.size());
  for (const sim::Pole& p : poles_) out.push_back({p.id, p.x_m, p.y_m});
  return out;
}

std::optional<std::uint16_t> HardwareEmulator::signature_of(int landmark_id) const {
  const auto it = signature_of_.find(landmark_id);
  if (it == signature_of_.end()) return std::nullopt;
  return it->second;
}

double HardwareEmulator::arduino_time_s(std::uint64_t k) const {
  return static_cast<double>(k) / hw_.arduino_rate_hz;
}

double HardwareEmulator::pixy_time_s(std::uint64_t j) const { return static_cast<double>(j) / hw_.pixy_rate_hz; }

HardwareOutput HardwareEmulator::advance_to(double t_s) {
  if (!std::isfinite(t_s)) throw std::invalid_argument("HardwareEmulator::advance_to: time must be finite");
  HardwareOutput out;
  if (t_s < 0.0) return out;
  if (!started_) {
    started_ = true;
    encoder::EncoderReset reset;
    reset.firmware_version = hw_.firmware_version;
    reset.ticks_per_revolution = static_cast<std::uint32_t>(encoder_.ticks_per_revolution);
    out.arduino_bytes += encoder::format_line(reset);
    ++counters_.arduino_lines;
  }
  // Events on two fixed grids, the Arduino's first at equal times.
  for (;;) {
    const double ta = arduino_time_s(next_sample_);
    const double tp = pixy_time_s(next_frame_);
    const double te = std::min(ta, tp);
    if (te > t_s) break;
    integrate_to(te);
    event_time_s_ = te;
    if (ta <= tp) {
      emit_encoder_sample(out);
    } else {
      emit_pixy_frame(out);
    }
  }
  return out;
}

void HardwareEmulator::integrate_to(double t_s) {
  const double span = t_s - state_time_s_;
  if (span <= 0.0) return;
  const auto n = static_cast<long>(std::max(1.0, std::ceil(span / hw_.physics_step_s - 1e-9)));
  const double h = span / static_cast<double>(n);
  for (long i = 0; i < n; ++i) {
    const double a = state_time_s_ + static_cast<double>(i) * h;
    const double b = i + 1 == n ? t_s : a + h;
    // The path's command is piecewise constant with pieces far longer than a
    // step: a step holds at most one switch, found by bisection, so the
    // integration is exact up to rounding.
    const sim::PathCommand ca = path_.command_at(a);
    const sim::PathCommand cb = path_.command_at(b);
    if (ca.v_mps == cb.v_mps && ca.w_radps == cb.w_radps) {
      step_exactly(ca, b - a);
      continue;
    }
    double lo = a, hi = b;
    for (int k = 0; k < 60 && hi - lo > 1e-12; ++k) {
      const double mid = 0.5 * (lo + hi);
      const sim::PathCommand cm = path_.command_at(mid);
      (cm.v_mps == ca.v_mps && cm.w_radps == ca.w_radps ? lo : hi) = mid;
    }
    step_exactly(ca, hi - a);
    step_exactly(cb, b - hi);
  }
  state_time_s_ = t_s;
}

void HardwareEmulator::step_exactly(const sim::PathCommand& c, double h) {
  if (h <= 0.0) return;
  // Exact arc: a chord of length v h sinc(a/2) along the mean heading.
  const double a = c.w_radps * h;
  const double chord = c.v_mps * h * sinc(0.5 * a);
  const double heading = pose_.z() + 0.5 * a;
  pose_ = slam::Pose2(pose_.x() + chord * std::cos(heading), pose_.y() + chord * std::sin(heading),
                      slam::wrap_angle(pose_.z() + a));
  // Wheel travel as the encoders see it: true speed plus the interval's noise.
  const double half_base = 0.5 * encoder_.wheel_base_m;
  left_travel_m_ += (c.v_mps - half_base * c.w_radps + noise_v_mps_ - half_base * noise_w_radps_) * h;
  right_travel_m_ += (c.v_mps + half_base * c.w_radps + noise_v_mps_ + half_base * noise_w_radps_) * h;
}

void HardwareEmulator::emit_encoder_sample(HardwareOutput& out) {
  const std::uint64_t k = next_sample_++;
  const double t = arduino_time_s(k);
  const auto counter = [&](int sign, double travel_m) {
    // Whole ticks of the travel so far; the fraction stays in travel_m.
    const auto ticks = static_cast<std::int64_t>(std::floor(travel_m / metres_per_tick_));
    return wrap_int32(static_cast<std::int64_t>(hw_.start_ticks) + sign * ticks);
  };
  encoder::EncoderSample s;
  s.seq = static_cast<std::uint32_t>(k);
  const auto micros = static_cast<std::uint64_t>(std::llround(t * 1e6));
  s.arduino_time_us = static_cast<std::uint32_t>(hw_.arduino_start_time_us + micros);  // modulo 2^32
  s.left_ticks = counter(encoder_.left_sign, left_travel_m_);
  s.right_ticks = counter(encoder_.right_sign, right_travel_m_);
  out.arduino_bytes += encoder::format_line(s);
  out.encoder_samples.push_back({t, s});
  out.truth.push_back({t, pose_.x(), pose_.y(), pose_.z()});
  ++counters_.arduino_lines;

  // Noise of the interval that starts now (white: a density, see HardwareOptions).
  noise_v_mps_ = hw_.v_sigma_mps * wheel_noise_scale_ * wheel_normal_(wheel_rng_);
  noise_w_radps_ = hw_.w_sigma_radps * wheel_noise_scale_ * wheel_normal_(wheel_rng_);
}

void HardwareEmulator::emit_pixy_frame(HardwareOutput& out) {
  const std::uint64_t j = next_frame_++;
  ++counters_.pixy_frames;
  PixyFrameRecord rec;
  rec.t_s = pixy_time_s(j);
  rec.pose = {rec.t_s, pose_.x(), pose_.y(), pose_.z()};

  const pixy::CameraModel& cam = camera_;
  const double iw = cam.image_width_px;
  const double ih = cam.image_height_px;
  const double width_px_m = hw_.pole_width_m * pixy::px_per_tan(cam);  // block width times range
  const double cos_t = std::cos(pose_.z());
  const double sin_t = std::sin(pose_.z());

  for (const sim::Pole& pole : poles_) {
    const auto sig = signature_of_.find(pole.id);
    if (sig == signature_of_.end()) continue;  // not marked: the camera cannot tell it
    const double dx = pole.x_m - pose_.x();
    const double dy = pole.y_m - pose_.y();
    const double forward = cos_t * dx + sin_t * dy;
    const double left = -sin_t * dx + cos_t * dy;
    if (forward <= 0.0) {
      ++counters_.behind_camera;
      continue;
    }
    PoleSighting s;
    s.landmark_id = pole.id;
    s.true_range_m = std::hypot(forward, left);
    s.true_bearing_rad = std::atan2(left, forward);
    if (s.true_range_m < hw_.min_range_m || s.true_range_m > hw_.max_range_m) {
      ++counters_.out_of_range;
      continue;
    }
    s.noisy_range_m = s.true_range_m + hw_.range_sigma_m * camera_normal_(camera_rng_);
    s.noisy_bearing_rad = s.true_bearing_rad + hw_.bearing_sigma_rad * camera_normal_(camera_rng_);
    if (!(s.noisy_range_m > 0.0) || std::abs(s.noisy_bearing_rad) >= 0.5 * kPi) {
      ++counters_.outside_image;
      continue;
    }
    // The pole's image (Eq. 5 and 6 inverted), cut to the image.
    const double h = pixy::block_height_px(cam, s.noisy_range_m);
    const double w = width_px_m / s.noisy_range_m;
    const double xc = pixy::block_x_px(cam, s.noisy_bearing_rad);
    const double left_px = xc - 0.5 * w, right_px = xc + 0.5 * w;
    const double top_px = 0.5 * ih - 0.5 * h, bottom_px = 0.5 * ih + 0.5 * h;
    const double x0 = std::max(left_px, 0.0);
    const double x1 = std::min(right_px, iw);
    const double y0 = std::max(top_px, 0.0);
    const double y1 = std::min(bottom_px, ih);
    if (!(x1 > x0)) {
      ++counters_.outside_image;
      continue;
    }
    s.clipped = left_px < 0.0 || right_px > iw || top_px < 0.0 || bottom_px > ih;
    pixy::PixyBlock& b = s.block;
    b.signature = sig->second;
    b.colour_code = sig->second > 7;
    b.angle_deg = static_cast<std::int16_t>(b.colour_code ? hw_.colour_code_angle_deg : 0);
    b.x = pixel(0.5 * (x0 + x1), cam.image_width_px - 1);
    b.y = pixel(0.5 * (y0 + y1), cam.image_height_px - 1);
    b.width = pixel(x1 - x0, cam.image_width_px);
    b.height = pixel(y1 - y0, cam.image_height_px);
    const long area = static_cast<long>(b.width) * b.height;
    if (b.width == 0 || b.height == 0 || area < hw_.min_block_area_px) {
      ++counters_.too_small;
      continue;
    }
    rec.sightings.push_back(s);
  }

  // Largest block first, as the camera sends them.
  std::stable_sort(rec.sightings.begin(), rec.sightings.end(), [](const PoleSighting& a, const PoleSighting& b) {
    return static_cast<long>(a.block.width) * a.block.height > static_cast<long>(b.block.width) * b.block.height;
  });
  if (!rec.sightings.empty() || hw_.send_empty_frames) {
    std::vector<pixy::PixyBlock> blocks;
    blocks.reserve(rec.sightings.size());
    for (const PoleSighting& s : rec.sightings) {
      blocks.push_back(s.block);
      if (s.clipped) ++counters_.blocks_clipped;
    }
    const std::vector<std::uint8_t> bytes = pixy::encode_frame(blocks);
    out.pixy_bytes.insert(out.pixy_bytes.end(), bytes.begin(), bytes.end());
    rec.sent = true;
    ++counters_.pixy_frames_sent;
    counters_.blocks_sent += blocks.size();
  }
  out.frames.push_back(std::move(rec));
}

}  // namespace pixyslam::robot_sim
