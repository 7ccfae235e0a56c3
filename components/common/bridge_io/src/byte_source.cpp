#include "pixyslam/bridge/byte_source.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace pixyslam::bridge {

SerialByteSource::SerialByteSource(std::string path, long baud) : path_(std::move(path)), baud_(baud) {}

void SerialByteSource::open() { port_.open(path_, baud_); }

void SerialByteSource::close() { port_.close(); }

bool SerialByteSource::is_open() const { return port_.is_open(); }

serial::ReadResult SerialByteSource::read_some(std::uint8_t* buffer, std::size_t max,
                                               std::chrono::milliseconds timeout) {
  return port_.read_some(buffer, max, timeout);
}

std::string SerialByteSource::name() const { return path_; }

void ByteScript::push(Event event) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    events_.push_back(std::move(event));
  }
  changed_.notify_all();
}

void ByteScript::add_bytes(const std::vector<std::uint8_t>& bytes, std::uint64_t at_ns) {
  if (bytes.empty()) return;
  Event e;
  e.bytes = bytes;
  e.at_ns = at_ns;
  push(std::move(e));
}

void ByteScript::add_bytes(std::string_view bytes, std::uint64_t at_ns) {
  add_bytes(std::vector<std::uint8_t>(bytes.begin(), bytes.end()), at_ns);
}

void ByteScript::add_idle(std::uint64_t until_ns) {
  Event e;
  e.kind = Event::Kind::kIdle;
  e.at_ns = until_ns;
  push(std::move(e));
}

void ByteScript::add_hangup(std::uint64_t at_ns) {
  Event e;
  e.kind = Event::Kind::kHangup;
  e.at_ns = at_ns;
  push(std::move(e));
}

void ByteScript::fail_next_opens(int count) {
  std::lock_guard<std::mutex> lock(mutex_);
  failing_opens_ += count;
}

std::uint64_t ByteScript::now_ns() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return now_ns_;
}

bool ByteScript::finished() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return events_.empty();
}

bool ByteScript::wait_finished(std::chrono::milliseconds timeout) const {
  std::unique_lock<std::mutex> lock(mutex_);
  return changed_.wait_for(lock, timeout, [this] { return events_.empty(); });
}

int ByteScript::opens() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return opens_;
}

std::function<std::uint64_t()> ByteScript::clock(const std::shared_ptr<ByteScript>& script) {
  return [script] { return script->now_ns(); };
}

bool ByteScript::try_open() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (failing_opens_ > 0) {
    --failing_opens_;
    return false;
  }
  ++opens_;
  return true;
}

serial::ReadResult ByteScript::read(std::uint8_t* buffer, std::size_t max, std::chrono::milliseconds timeout) {
  serial::ReadResult result;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    if (!changed_.wait_for(lock, timeout, [this] { return !events_.empty(); })) return result;
    Event& e = events_.front();
    now_ns_ = std::max(now_ns_, e.at_ns);
    switch (e.kind) {
      case Event::Kind::kIdle:
        break;
      case Event::Kind::kHangup:
        result.status = serial::ReadStatus::kHangup;
        break;
      case Event::Kind::kBytes: {
        const std::size_t n = std::min(max, e.bytes.size() - e.taken);
        std::copy_n(e.bytes.begin() + static_cast<std::ptrdiff_t>(e.taken), n, buffer);
        e.taken += n;
        result.status = serial::ReadStatus::kData;
        result.bytes = n;
        if (e.taken < e.bytes.size()) return result;  // the rest on the next read
        break;
      }
    }
    events_.pop_front();
  }
  changed_.notify_all();
  return result;
}

ScriptedByteSource::ScriptedByteSource(std::shared_ptr<ByteScript> script, std::string name)
    : script_(std::move(script)), name_(std::move(name)) {}

void ScriptedByteSource::open() {
  if (!script_->try_open()) throw std::runtime_error(name_ + ": open failed (scripted)");
  open_ = true;
}

serial::ReadResult ScriptedByteSource::read_some(std::uint8_t* buffer, std::size_t max,
                                                 std::chrono::milliseconds timeout) {
  if (!open_) throw std::logic_error(name_ + ": read_some on a closed source");
  return script_->read(buffer, max, timeout);
}

}  // namespace pixyslam::bridge
