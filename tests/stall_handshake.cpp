// A fault for tests (LD_PRELOAD): the first DDS participant of this process
// that sends a DDS Security authentication handshake message never gets one
// through. Every handshake datagram it sends is lost, so its handshakes stay
// pending for good, as Fast DDS 2.9 sometimes leaves one (docs/security.md).
// A later participant of the same process (another GUID prefix) is not
// touched, nor is any other datagram.
// A handshake message carries its class id in the clear
// ("DDS:Auth:PKI-DH:1.0+Req", "+Reply", "+Final"); an RTPS datagram starts
// with "RTPS", the version, the vendor id and the sender's GUID prefix.
#include <dlfcn.h>
#include <sys/socket.h>
#include <sys/types.h>

#include <array>
#include <cstdio>
#include <cstring>
#include <mutex>

namespace {

constexpr char kHandshake[] = "DDS:Auth:PKI-DH:1.0+";
constexpr std::size_t kPrefixAt = 8, kPrefixLen = 12;

std::mutex mu;
std::array<unsigned char, kPrefixLen> stalled;
bool have_stalled = false;
unsigned long lost = 0;

/// Whether to lose this outgoing datagram: a handshake message of the stalled participant.
bool lose(const void* data, std::size_t len) {
  const auto* buf = static_cast<const unsigned char*>(data);
  if (!buf || len < kPrefixAt + kPrefixLen || std::memcmp(buf, "RTPS", 4) != 0 ||
      !memmem(buf, len, kHandshake, sizeof kHandshake - 1))
    return false;
  const std::lock_guard<std::mutex> lock(mu);
  if (!have_stalled) {
    std::memcpy(stalled.data(), buf + kPrefixAt, kPrefixLen);
    have_stalled = true;
    std::fprintf(stderr,
                 "stall_handshake: this participant's handshake messages are lost from now on\n");
  }
  if (std::memcmp(stalled.data(), buf + kPrefixAt, kPrefixLen) != 0) return false;
  ++lost;
  if ((lost & (lost - 1)) == 0)
    std::fprintf(stderr, "stall_handshake: %lu handshake messages lost\n", lost);
  return true;
}

template <class F>
F* real(const char* name) {
  return reinterpret_cast<F*>(dlsym(RTLD_NEXT, name));
}

}  // namespace

extern "C" ssize_t sendmsg(int fd, const struct msghdr* m, int flags) {
  static auto* next = real<ssize_t(int, const struct msghdr*, int)>("sendmsg");
  // Fast DDS sends a datagram from one buffer.
  if (m->msg_iovlen == 1 && lose(m->msg_iov[0].iov_base, m->msg_iov[0].iov_len))
    return static_cast<ssize_t>(m->msg_iov[0].iov_len);
  return next(fd, m, flags);
}

extern "C" ssize_t sendto(int fd, const void* buf, size_t len, int flags, const struct sockaddr* to,
                          socklen_t tl) {
  static auto* next =
      real<ssize_t(int, const void*, size_t, int, const struct sockaddr*, socklen_t)>("sendto");
  if (lose(buf, len)) return static_cast<ssize_t>(len);
  return next(fd, buf, len, flags, to, tl);
}
