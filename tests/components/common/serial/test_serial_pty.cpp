// Tests of the POSIX serial layer on a pseudo-terminal pair: a byte stream in
// random chunks arrives in order both ways, read timeouts, hang-ups, the
// slave kept open across client restarts, the drop policy when nobody reads,
// error messages (missing device, unsupported rate, not a terminal) and the
// symbolic link's life cycle.

#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "pixyslam/serial/pseudo_terminal.h"
#include "pixyslam/serial/serial_port.h"
#include "temp_dir.h"

namespace pixyslam::serial {
namespace {

using std::chrono::milliseconds;
using Millis = std::chrono::duration<double, std::milli>;
using Clock = std::chrono::steady_clock;

std::vector<std::uint8_t> random_bytes(std::size_t n, std::uint32_t seed) {
  std::mt19937 prng(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  std::vector<std::uint8_t> v(n);
  for (auto& b : v) b = static_cast<std::uint8_t>(byte(prng));
  return v;
}

// Reads until `want` bytes arrived (or a read times out after 2 s).
template <class Reader>
std::vector<std::uint8_t> read_exactly(Reader& r, std::size_t want) {
  std::vector<std::uint8_t> got;
  std::vector<std::uint8_t> buf(4096);
  while (got.size() < want) {
    const ReadResult res = r.read_some(buf.data(), buf.size(), milliseconds(2000));
    if (res.status != ReadStatus::kData) {
      ADD_FAILURE() << "read ended with status " << static_cast<int>(res.status) << " after " << got.size()
                    << " of " << want << " bytes";
      break;
    }
    got.insert(got.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(res.bytes));
  }
  return got;
}

bool is_symlink(const std::string& path) {
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0 && S_ISLNK(st.st_mode);
}

bool exists(const std::string& path) {
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0;
}

TEST(SerialPty, RandomChunksArriveInOrderBothWays) {
  PseudoTerminal pty;
  SerialPort port(pty.slave_path(), 115200);
  EXPECT_TRUE(port.is_open());
  EXPECT_EQ(port.baud(), 115200);

  // Given 100 kB of random bytes, when the master writes them in random chunks
  // (drained after each chunk), then the port reads them all, in order.
  const std::vector<std::uint8_t> down = random_bytes(100000, 1);
  std::mt19937 prng(42);
  std::uniform_int_distribution<std::size_t> chunk(1, 3000);
  std::vector<std::uint8_t> got;
  for (std::size_t pos = 0; pos < down.size();) {
    const std::size_t n = std::min(chunk(prng), down.size() - pos);
    ASSERT_EQ(pty.write_all(down.data() + pos, n), n);
    pos += n;
    const std::vector<std::uint8_t> part = read_exactly(port, pos - got.size());
    got.insert(got.end(), part.begin(), part.end());
  }
  EXPECT_EQ(got, down);
  EXPECT_EQ(pty.counters().written_bytes, down.size());
  EXPECT_EQ(pty.counters().dropped_bytes, 0u);

  // And back: the port writes, the master reads.
  const std::vector<std::uint8_t> up = random_bytes(100000, 2);
  got.clear();
  for (std::size_t pos = 0; pos < up.size();) {
    const std::size_t n = std::min(chunk(prng), up.size() - pos);
    port.write_all(up.data() + pos, n);
    pos += n;
    const std::vector<std::uint8_t> part = read_exactly(pty, pos - got.size());
    got.insert(got.end(), part.begin(), part.end());
  }
  EXPECT_EQ(got, up);
}

TEST(SerialPty, WriterWaitsForRoomWhileAReaderDrains) {
  // 400 kB is several times the kernel's pty buffer: the writer must wait in
  // poll() for room (EAGAIN) instead of dropping, since its timeout is long.
  PseudoTerminal pty("", milliseconds(20000));
  SerialPort port(pty.slave_path(), 115200);
  const std::vector<std::uint8_t> data = random_bytes(400000, 3);
  std::size_t written = 0;
  std::thread writer([&] {
    std::mt19937 prng(7);
    std::uniform_int_distribution<std::size_t> chunk(1, 20000);
    for (std::size_t pos = 0; pos < data.size();) {
      const std::size_t n = std::min(chunk(prng), data.size() - pos);
      written += pty.write_all(data.data() + pos, n);
      pos += n;
    }
  });
  const std::vector<std::uint8_t> got = read_exactly(port, data.size());
  writer.join();
  EXPECT_EQ(written, data.size());
  EXPECT_EQ(got, data);
  EXPECT_EQ(pty.counters().dropped_bytes, 0u);
  EXPECT_EQ(pty.counters().stalls, 0u);
}

TEST(SerialPty, CrLfAndEveryByteValuePassUnchanged) {
  PseudoTerminal pty;
  SerialPort port(pty.slave_path(), 9600);
  std::vector<std::uint8_t> all(256);
  for (int i = 0; i < 256; ++i) all[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(i);
  const std::string line = "$ENC,1,20000,12,-7*52\r\n";
  ASSERT_EQ(pty.write_all(line), line.size());
  ASSERT_EQ(pty.write_all(all), all.size());
  const std::vector<std::uint8_t> got = read_exactly(port, line.size() + all.size());
  EXPECT_EQ(std::string(got.begin(), got.begin() + static_cast<std::ptrdiff_t>(line.size())), line);
  EXPECT_EQ(std::vector<std::uint8_t>(got.begin() + static_cast<std::ptrdiff_t>(line.size()), got.end()), all);
  // Nothing was echoed back to the master.
  std::uint8_t b = 0;
  EXPECT_EQ(pty.read_some(&b, 1, milliseconds(50)).status, ReadStatus::kTimeout);
}

TEST(SerialPty, ReadTimeoutReturnsNothingWithinBound) {
  PseudoTerminal pty;
  SerialPort port(pty.slave_path(), 115200);
  std::uint8_t buf[16];
  const auto t0 = Clock::now();
  const ReadResult r = port.read_some(buf, sizeof buf, milliseconds(100));
  const double elapsed_ms = Millis(Clock::now() - t0).count();
  EXPECT_EQ(r.status, ReadStatus::kTimeout);
  EXPECT_EQ(r.bytes, 0u);
  EXPECT_GE(elapsed_ms, 99.0);
  EXPECT_LT(elapsed_ms, 1000.0);
  // A zero timeout does not wait.
  const auto t1 = Clock::now();
  EXPECT_EQ(port.read_some(buf, sizeof buf, milliseconds(0)).status, ReadStatus::kTimeout);
  const double zero_ms = Millis(Clock::now() - t1).count();
  EXPECT_LT(zero_ms, 100.0);
}

TEST(SerialPty, ClosingTheMasterIsAHangup) {
  auto pty = std::make_unique<PseudoTerminal>();
  SerialPort port(pty->slave_path(), 115200);
  ASSERT_EQ(pty->write_all(std::string("abc")), 3u);
  pty.reset();  // the "device" is unplugged
  // Bytes already queued may still be read; then the hang-up is reported (not thrown).
  std::uint8_t buf[16];
  ReadResult r = port.read_some(buf, sizeof buf, milliseconds(1000));
  if (r.status == ReadStatus::kData) r = port.read_some(buf, sizeof buf, milliseconds(1000));
  EXPECT_EQ(r.status, ReadStatus::kHangup);
  EXPECT_THROW(port.write_all(std::string("x"), milliseconds(100)), std::system_error);
}

// Two readers of one device would each get part of its bytes: the second open
// is refused, naming the device, until the first port closes.
TEST(SerialPty, ASecondOpenOfTheSameDeviceIsRefusedUntilTheFirstCloses) {
  PseudoTerminal pty;
  {
    SerialPort first(pty.slave_path(), 115200);
    try {
      SerialPort second(pty.slave_path(), 115200);
      ADD_FAILURE() << "a second open of " << pty.slave_path() << " succeeded";
    } catch (const std::system_error& e) {
      EXPECT_EQ(e.code().value(), EBUSY);
      EXPECT_NE(std::string(e.what()).find(pty.slave_path() + ": in use by another process"), std::string::npos)
          << e.what();
    }
    ASSERT_EQ(pty.write_all(std::string("ok")), 2u);
    EXPECT_EQ(read_exactly(first, 2), std::vector<std::uint8_t>({'o', 'k'}));
  }
  SerialPort again(pty.slave_path(), 115200);  // free once the first closed
  ASSERT_EQ(pty.write_all(std::string("go")), 2u);
  EXPECT_EQ(read_exactly(again, 2), std::vector<std::uint8_t>({'g', 'o'}));
}

TEST(SerialPty, ClientRestartDoesNotHangTheMasterUp) {
  PseudoTerminal pty;
  {
    SerialPort port(pty.slave_path(), 115200);
    ASSERT_EQ(pty.write_all(std::string("first")), 5u);
    EXPECT_EQ(read_exactly(port, 5), std::vector<std::uint8_t>({'f', 'i', 'r', 's', 't'}));
  }  // the bridge exits
  // The master sees no hang-up and still accepts bytes (queued for the next client).
  std::uint8_t buf[16];
  EXPECT_EQ(pty.read_some(buf, sizeof buf, milliseconds(50)).status, ReadStatus::kTimeout);
  EXPECT_EQ(pty.write_all(std::string("stale")), 5u);
  // The kernel moves written bytes to the slave's queue asynchronously.
  const auto deadline = Clock::now() + milliseconds(2000);
  while (pty.queued_bytes() < 5 && Clock::now() < deadline) std::this_thread::sleep_for(milliseconds(1));
  EXPECT_EQ(pty.queued_bytes(), 5u);
  // The bridge restarts: stale input is discarded on open, new bytes arrive.
  SerialPort port(pty.slave_path(), 115200);
  EXPECT_EQ(pty.queued_bytes(), 0u);
  ASSERT_EQ(pty.write_all(std::string("fresh")), 5u);
  EXPECT_EQ(read_exactly(port, 5), std::vector<std::uint8_t>({'f', 'r', 'e', 's', 'h'}));
  EXPECT_EQ(pty.counters().dropped_bytes, 0u);
}

TEST(SerialPty, NobodyReadingDropsAfterTheTimeoutAndKeepsPace) {
  // Given no client on the slave and a 200 ms write timeout,
  PseudoTerminal pty("", milliseconds(200));
  const std::vector<std::uint8_t> big = random_bytes(1 << 20, 4);
  // when 1 MB is written, the kernel queue fills, the write gives up after
  // about the timeout and drops the rest;
  auto t0 = Clock::now();
  const std::size_t n = pty.write_all(big);
  double ms = Millis(Clock::now() - t0).count();
  EXPECT_LT(n, big.size());
  EXPECT_GT(n, 1000u);
  EXPECT_GE(ms, 190.0);
  EXPECT_LT(ms, 3000.0);
  EXPECT_TRUE(pty.stalled());
  EXPECT_EQ(pty.counters().stalls, 1u);
  EXPECT_EQ(pty.counters().dropped_bytes, big.size() - n);
  // then, stalled, later writes drop at once instead of waiting again.
  t0 = Clock::now();
  EXPECT_EQ(pty.write_all(std::string(100, 'x')), 0u);
  ms = Millis(Clock::now() - t0).count();
  EXPECT_LT(ms, 150.0);
  EXPECT_EQ(pty.counters().stalls, 1u);
  EXPECT_EQ(pty.counters().dropped_bytes, big.size() - n + 100);
  // When a client opens the slave (discarding the stale queue), writes go
  // through again and the stall ends.
  SerialPort port(pty.slave_path(), 115200);
  ASSERT_EQ(pty.write_all(std::string("hello")), 5u);
  EXPECT_FALSE(pty.stalled());
  EXPECT_EQ(read_exactly(port, 5), std::vector<std::uint8_t>({'h', 'e', 'l', 'l', 'o'}));
}

TEST(SerialPty, MissingDeviceThrowsWithThePath) {
  const std::string path = "/dev/pixyslam_no_such_tty_0";
  try {
    SerialPort port(path, 115200);
    FAIL() << "expected std::system_error";
  } catch (const std::system_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("No such file or directory"), std::string::npos) << what;
    EXPECT_EQ(e.code(), std::errc::no_such_file_or_directory);
  }
  SerialPort closed;
  std::uint8_t b = 0;
  EXPECT_THROW(closed.read_some(&b, 1, milliseconds(0)), std::logic_error);
}

TEST(SerialPty, UnsupportedBaudListsTheSupportedOnes) {
  PseudoTerminal pty;
  try {
    SerialPort port(pty.slave_path(), 12345);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(pty.slave_path()), std::string::npos) << what;
    EXPECT_NE(what.find("12345"), std::string::npos) << what;
    EXPECT_NE(what.find("9600, 19200"), std::string::npos) << what;
    EXPECT_NE(what.find("115200"), std::string::npos) << what;
  }
  EXPECT_TRUE(is_supported_baud(115200));
  EXPECT_TRUE(is_supported_baud(50));
  EXPECT_FALSE(is_supported_baud(0));
  EXPECT_FALSE(is_supported_baud(115201));
  EXPECT_EQ(supported_bauds().front(), 50);
}

TEST(SerialPty, NonTerminalIsRejected) {
  try {
    SerialPort port("/dev/null", 115200);
    FAIL() << "expected std::system_error";
  } catch (const std::system_error& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/null"), std::string::npos) << e.what();
  }
}

TEST(SerialPty, SymlinkIsCreatedReplacedAndRemoved) {
  const test::TempDir dir;
  const std::string link = dir.path() + "/tty";
  std::string slave;
  {
    PseudoTerminal pty(link);
    slave = pty.slave_path();
    EXPECT_EQ(pty.link_path(), link);
    EXPECT_EQ(pty.device_path(), link);
    ASSERT_TRUE(is_symlink(link));
    // A client opens the link like a real device.
    SerialPort port(link, 115200);
    ASSERT_EQ(pty.write_all(std::string("via link")), 8u);
    EXPECT_EQ(read_exactly(port, 8).size(), 8u);
  }
  EXPECT_FALSE(exists(link));

  // A stale link (dangling, from a crashed run) is replaced.
  ASSERT_EQ(::symlink("/dev/pts/pixyslam_gone", link.c_str()), 0);
  {
    PseudoTerminal pty(link);
    std::array<char, 256> buf{};
    const ssize_t n = ::readlink(link.c_str(), buf.data(), buf.size() - 1);
    ASSERT_GT(n, 0);
    EXPECT_EQ(std::string(buf.data(), static_cast<std::size_t>(n)), pty.slave_path());
  }
  EXPECT_FALSE(exists(link));

  // A regular file is never replaced.
  const std::string file = dir.path() + "/file";
  std::ofstream(file) << "precious";
  try {
    PseudoTerminal pty(file);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
  }
  std::ifstream in(file);
  std::string content;
  in >> content;
  EXPECT_EQ(content, "precious");
}

}  // namespace
}  // namespace pixyslam::serial
