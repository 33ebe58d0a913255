// POSIX host HAL for the reference controller (see host_hal.hpp).
#include "texel/controller/host_hal.hpp"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <termios.h>
#include <unistd.h>

#include "texel/error.hpp"

namespace texel::controller {

namespace {
speed_t baud_constant(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 921600: return B921600;
    case 1000000: return B1000000;
    case 2000000: return B2000000;
    default: return 0;
  }
}
}  // namespace

void make_raw(int fd, int baud) {
  termios t{};
  if (tcgetattr(fd, &t) != 0) return;  // not a terminal (a pipe in a test): nothing to set
  cfmakeraw(&t);
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  if (const speed_t s = baud_constant(baud)) {
    cfsetispeed(&t, s);
    cfsetospeed(&t, s);
  }
  tcsetattr(fd, TCSANOW, &t);
}

int open_serial_port(const std::string& path, int baud) {
  if (baud_constant(baud) == 0)
    throw InvalidArgument("serial: baud is " + std::to_string(baud) +
                          "; allowed 9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600, 1000000, 2000000");
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw IoError("serial: cannot open '" + path + "': " + std::strerror(errno));
  make_raw(fd, baud);
  return fd;
}

HostHal::HostHal(int fd) : fd_(fd) {
  const int flags = fcntl(fd_, F_GETFL);
  if (flags >= 0) fcntl(fd_, F_SETFL, flags | O_NONBLOCK);
  tx_.reserve(tx_capacity);
}

HostHal::~HostHal() { close_link(); }

void HostHal::close_link() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  down_ = true;
}

std::uint32_t HostHal::micros() {
  using namespace std::chrono;
  return static_cast<std::uint32_t>(duration_cast<microseconds>(steady_clock::now().time_since_epoch()).count());
}

int HostHal::serial_read(std::uint8_t* buf, int max) {
  if (fd_ < 0) return -1;
  if (!flush()) {
    down_ = true;
    return -1;
  }
  const ssize_t n = ::read(fd_, buf, static_cast<std::size_t>(max));
  if (n > 0) {
    down_ = false;
    return static_cast<int>(n);
  }
  if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) return 0;
  down_ = true;  // EIO (pty peer closed), EOF (hang-up) or another error
  return -1;
}

bool HostHal::flush() {
  while (tx_head_ < tx_.size()) {
    const ssize_t w = ::write(fd_, tx_.data() + tx_head_, tx_.size() - tx_head_);
    if (w > 0) {
      tx_head_ += static_cast<std::size_t>(w);
    } else if (w < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) {
      break;  // the link takes no more now: the rest waits in the queue
    } else {
      return false;
    }
  }
  if (tx_head_ == tx_.size()) {
    tx_.clear();
    tx_head_ = 0;
  } else if (tx_head_ > tx_capacity / 2) {
    tx_.erase(tx_.begin(), tx_.begin() + static_cast<std::ptrdiff_t>(tx_head_));
    tx_head_ = 0;
  }
  return true;
}

bool HostHal::serial_write(const std::uint8_t* buf, int n) {
  if (fd_ < 0) return false;
  if (!flush()) return false;
  const auto bytes = static_cast<std::size_t>(n);
  if (tx_.size() + bytes > tx_capacity) {
    tx_dropped.fetch_add(1, std::memory_order_relaxed);  // the host stopped reading: this frame is lost whole
    return true;
  }
  tx_.insert(tx_.end(), buf, buf + n);
  return flush();
}

bool HostHal::read_position(std::int32_t& x_nm, bool& touch) {
  std::int32_t y_nm = 0;
  return sensor_2d ? sensor_2d(x_nm, y_nm, touch) : sensor ? sensor(x_nm, touch) : false;
}

bool HostHal::read_position_2d(std::int32_t& x_nm, std::int32_t& y_nm, bool& touch) {
  if (sensor_2d) return sensor_2d(x_nm, y_nm, touch);
  y_nm = 0;
  return sensor ? sensor(x_nm, touch) : false;
}

void HostHal::write_amplitude(std::uint16_t a) {
  amplitude.store(a, std::memory_order_relaxed);
  writes.fetch_add(1, std::memory_order_relaxed);
}

void HostHal::on_tick(std::uint32_t t_us, const Status& status) {
  if (tick_observer) tick_observer(t_us, status);
}

void HostHal::idle_until(std::uint32_t t_us) {
  const auto wait_us = static_cast<std::int32_t>(t_us - micros());
  if (down_ || fd_ < 0) {
    // The link is down: poll() would report POLLHUP at once; retry gently.
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return;
  }
  if (wait_us <= 0) return;
  // The default 50 µs timer slack is close to the 120 µs tick; ask for 1 µs.
  thread_local const bool slack_set = ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL) == 0;
  (void)slack_set;
  pollfd p{fd_, POLLIN, 0};
  const timespec ts{0, static_cast<long>(wait_us) * 1000L};
  ::ppoll(&p, 1, &ts, nullptr);
}

}  // namespace texel::controller
