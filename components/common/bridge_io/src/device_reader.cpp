#include "pixyslam/bridge/device_reader.h"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <utility>
#include <vector>

namespace pixyslam::bridge {
namespace {
std::string seconds_text(std::uint64_t now_ns, std::uint64_t since_ns) {
  char text[32];
  const std::uint64_t elapsed_ns = now_ns > since_ns ? now_ns - since_ns : 0;  // the host clock may step back
  std::snprintf(text, sizeof text, "%.1f", static_cast<double>(elapsed_ns) * 1e-9);
  return text;
}
}  // namespace

LogFunction stderr_log(const std::string& process) {
  return [process](const std::string& line) {
    std::fprintf(stderr, "%s: %s\n", process.c_str(), line.c_str());
  };
}

DeviceReader::DeviceReader(std::unique_ptr<ByteSource> source, const DeviceReaderOptions& options,
                           LogFunction log, ClockFunction clock)
    : source_(std::move(source)),
      device_name_(source_->name()),
      options_(options),
      log_(std::move(log)),
      clock_(std::move(clock)) {
  options_.poll_period = std::max(options_.poll_period, std::chrono::milliseconds(1));
  options_.buffer_bytes = std::max<std::size_t>(options_.buffer_bytes, 1);
}

DeviceReader::~DeviceReader() { stop(); }

void DeviceReader::start(Handlers handlers) {
  if (thread_.joinable()) return;
  handlers_ = std::move(handlers);
  stop_ = false;
  thread_ = std::thread([this] { loop(); });
}

void DeviceReader::stop() {
  {
    std::lock_guard<std::mutex> lock(wait_mutex_);
    stop_ = true;
  }
  wait_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

DeviceCounters DeviceReader::counters() const {
  std::lock_guard<std::mutex> lock(counters_mutex_);
  return counters_;
}

std::string DeviceReader::status_line() const {
  const DeviceCounters d = counters();
  return "status: device '" + device_name_ + "': opens " + std::to_string(d.opens) + ", open failures " +
         std::to_string(d.open_failures) + ", hang-ups " + std::to_string(d.hangups) + ", read errors " +
         std::to_string(d.read_errors) + ", bytes " + std::to_string(d.bytes) + ", silences " +
         std::to_string(d.silences) + (d.silent ? " (silent now)" : "");
}

std::chrono::milliseconds DeviceReader::read_timeout() {
  if (!handlers_.poll_deadline_ns) return options_.poll_period;
  std::uint64_t deadline_ns = 0;
  run_handler("poll_deadline_ns", [&] { deadline_ns = handlers_.poll_deadline_ns(); });
  if (deadline_ns == 0) return options_.poll_period;
  const std::uint64_t now_ns = clock_();
  const std::uint64_t wait_ns = deadline_ns > now_ns ? deadline_ns - now_ns : 0;
  const auto wait_ms = static_cast<long long>((wait_ns + 999'999) / 1'000'000);  // rounded up
  return std::clamp(std::chrono::milliseconds(wait_ms), std::chrono::milliseconds(1), options_.poll_period);
}

template <class Call>
void DeviceReader::run_handler(const char* name, const Call& call) {
  try {
    call();
  } catch (const std::exception& e) {
    {
      std::lock_guard<std::mutex> lock(counters_mutex_);
      ++counters_.handler_errors;
    }
    log_(std::string("error in ") + name + " (ignored): " + e.what());
  }
}

void DeviceReader::note_silence(std::uint64_t now_ns, std::uint64_t& last_bytes_ns) {
  if (options_.silence_warn.count() <= 0) return;
  if (now_ns < last_bytes_ns) last_bytes_ns = now_ns;  // the host clock stepped back
  const auto warn_ns = static_cast<std::uint64_t>(options_.silence_warn.count()) * 1'000'000u;
  if (now_ns - last_bytes_ns < warn_ns) return;
  {
    std::lock_guard<std::mutex> lock(counters_mutex_);
    if (counters_.silent) return;
    counters_.silent = true;
    ++counters_.silences;
  }
  log_("no bytes from serial device '" + device_name_ + "' for " + seconds_text(now_ns, last_bytes_ns) +
       " s (open, no hang-up): a pulled UART wire, the wrong device or baud rate, or a sender with nothing to send");
}

void DeviceReader::wait(std::chrono::milliseconds period) {
  const auto end = std::chrono::steady_clock::now() + period;
  while (!stopping()) {
    const auto now = std::chrono::steady_clock::now();
    if (now >= end) return;
    {
      std::unique_lock<std::mutex> lock(wait_mutex_);
      const auto slice = std::min<std::chrono::steady_clock::duration>(options_.poll_period, end - now);
      if (wait_cv_.wait_for(lock, slice, [this] { return stopping(); })) return;
    }
    if (handlers_.on_poll) run_handler("on_poll", [&] { handlers_.on_poll(clock_()); });
  }
}

void DeviceReader::loop() {
  std::vector<std::uint8_t> buffer(options_.buffer_bytes);
  char period_text[32];
  std::snprintf(period_text, sizeof period_text, "%g",
                static_cast<double>(options_.reopen_period.count()) / 1000.0);
  const std::string retry = std::string("retrying every ") + period_text + " s";
  std::uint64_t failures_in_row = 0;
  std::uint64_t last_bytes_ns = 0;  // host time of the last byte (or the open)
  std::string last_error;
  auto last_error_log = std::chrono::steady_clock::time_point{};

  while (!stopping()) {
    if (!source_->is_open()) {
      try {
        source_->open();
      } catch (const std::exception& e) {
        ++failures_in_row;
        {
          std::lock_guard<std::mutex> lock(counters_mutex_);
          ++counters_.open_failures;
        }
        const auto now = std::chrono::steady_clock::now();
        if (failures_in_row == 1 || e.what() != last_error ||
            now - last_error_log >= options_.repeat_error_log) {
          log_("cannot open serial device '" + device_name_ + "': " + e.what() + " (attempt " +
               std::to_string(failures_in_row) + "; " + retry + ")");
          last_error = e.what();
          last_error_log = now;
        }
        wait(options_.reopen_period);
        continue;
      }
      {
        std::lock_guard<std::mutex> lock(counters_mutex_);
        ++counters_.opens;
        counters_.silent = false;  // a silence is timed from this open
      }
      log_("opened serial device '" + device_name_ + "'" +
           (failures_in_row > 0 ? " after " + std::to_string(failures_in_row) + " failed attempts" : ""));
      failures_in_row = 0;
      last_error.clear();
      last_bytes_ns = clock_();
      if (handlers_.on_open) run_handler("on_open", [&] { handlers_.on_open(); });
    }

    serial::ReadResult result;
    try {
      result = source_->read_some(buffer.data(), buffer.size(), read_timeout());
    } catch (const std::exception& e) {
      {
        std::lock_guard<std::mutex> lock(counters_mutex_);
        ++counters_.read_errors;
      }
      log_("read error on serial device '" + device_name_ + "': " + e.what() + "; closing it, " + retry);
      source_->close();
      wait(options_.reopen_period);
      continue;
    }
    const std::uint64_t now_ns = clock_();
    if (result.status == serial::ReadStatus::kData && result.bytes > 0) {
      bool was_silent = false;
      {
        std::lock_guard<std::mutex> lock(counters_mutex_);
        ++counters_.reads;
        counters_.bytes += result.bytes;
        was_silent = std::exchange(counters_.silent, false);
      }
      if (was_silent) {
        log_("serial device '" + device_name_ + "' sends again after " + seconds_text(now_ns, last_bytes_ns) + " s");
      }
      last_bytes_ns = now_ns;
      if (handlers_.on_bytes) {
        run_handler("on_bytes", [&] { handlers_.on_bytes(buffer.data(), result.bytes, now_ns); });
      }
    } else if (result.status == serial::ReadStatus::kHangup) {
      {
        std::lock_guard<std::mutex> lock(counters_mutex_);
        ++counters_.hangups;
      }
      log_("serial device '" + device_name_ + "' hung up (unplugged or closed); " + retry);
      source_->close();
      if (handlers_.on_poll) run_handler("on_poll", [&] { handlers_.on_poll(now_ns); });
      wait(options_.reopen_period);
      continue;
    }
    if (result.status != serial::ReadStatus::kData) note_silence(now_ns, last_bytes_ns);
    if (handlers_.on_poll) run_handler("on_poll", [&] { handlers_.on_poll(now_ns); });
  }
  source_->close();
}

}  // namespace pixyslam::bridge
