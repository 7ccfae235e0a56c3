// LD_PRELOAD shim for programs run under qemu-user 7.2 (armhf tests only):
// qemu cannot translate setsockopt(IP_MULTICAST_IF) and fails it, after which
// Fast DDS sends nothing on that socket. This lets that one call succeed; the
// socket then sends through the default interface. Not for real hardware: a Pi
// runs the programs natively.
#include <dlfcn.h>
#include <netinet/in.h>
#include <sys/socket.h>

namespace {
using SetsockoptFn = int (*)(int, int, int, const void*, socklen_t);
}  // namespace

extern "C" int setsockopt(int fd, int level, int name, const void* value, socklen_t length) {
  static const auto real = reinterpret_cast<SetsockoptFn>(dlsym(RTLD_NEXT, "setsockopt"));
  const int result = real(fd, level, name, value, length);
  if (result != 0 && level == IPPROTO_IP && name == IP_MULTICAST_IF) return 0;
  return result;
}
