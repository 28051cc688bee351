// The live page's connections: one epoll thread holds every connection until a whole request has
// arrived, a few workers run complete requests (connection_pool.h).
#include "prizma/relight/connection_pool.h"

#include <poll.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <deque>
#include <map>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "prizma/spectral/error.h"

namespace prizma::relight {

namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// Past this many bytes without the blank line that ends a header, waiting cannot help: the worker
// reads it and cpp-httplib refuses it (414 / 400; its own limits are 8 KiB per line).
constexpr std::size_t kMaxHeaderBytes = 16384;

bool iequal_prefix(std::string_view text, std::string_view lower_prefix) {
  if (text.size() < lower_prefix.size()) return false;
  for (std::size_t i = 0; i < lower_prefix.size(); ++i) {
    const char c = text[i];
    if ((c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c) != lower_prefix[i]) return false;
  }
  return true;
}

// Waits until `fd` has one of `events` (or an error / hang-up, which the next recv or send reports);
// false when `timeout` passes first.
bool wait_for(int fd, short events, milliseconds timeout) {
  pollfd p{fd, events, 0};
  const auto end = Clock::now() + timeout;
  for (;;) {
    const auto left = std::chrono::duration_cast<milliseconds>(end - Clock::now()).count();
    if (left <= 0) return false;
    const int n = ::poll(&p, 1, static_cast<int>(std::min<long long>(left, 1000 * 60)));
    if (n > 0) return true;
    if (n < 0 && errno != EINTR) return true;  // let the caller's recv/send report it
  }
}

milliseconds until(Clock::time_point deadline) {
  return std::max(milliseconds(0), std::chrono::duration_cast<milliseconds>(deadline - Clock::now()));
}

}  // namespace

RequestProgress request_progress(std::string_view received, std::size_t max_body_bytes) {
  const std::size_t end = received.find("\r\n\r\n");
  if (end == std::string_view::npos) return {received.size() >= kMaxHeaderBytes, 0};
  const std::size_t header_bytes = end + 4;
  // Header lines after the request line: a body is announced by Content-Length or Transfer-Encoding.
  std::size_t body_bytes = 0;
  for (std::size_t pos = received.find("\r\n"); pos < end;) {
    const std::size_t next = received.find("\r\n", pos + 2);
    const std::string_view line = received.substr(pos + 2, next - pos - 2);
    pos = next;
    // A chunked body, or a client that waits for "100 Continue" before it sends its body.
    if (iequal_prefix(line, "transfer-encoding:") || iequal_prefix(line, "expect:")) return {true, header_bytes};
    if (!iequal_prefix(line, "content-length:")) continue;
    std::string_view value = line.substr(15);
    while (!value.empty() && (value.front() == ' ' || value.front() == '\t')) value.remove_prefix(1);
    while (!value.empty() && (value.back() == ' ' || value.back() == '\t')) value.remove_suffix(1);
    const auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), body_bytes);
    if (value.empty() || ec != std::errc() || ptr != value.data() + value.size() || body_bytes > max_body_bytes) {
      return {true, header_bytes};  // malformed or too large: the worker answers 400 / 413
    }
  }
  return {received.size() >= header_bytes + body_bytes, header_bytes};
}

Connection::Connection(int fd, std::string header, int requests_before, const ConnectionLimits& limits)
    : m_fd(fd),
      m_header(std::move(header)),
      m_requests_before(requests_before),
      m_limits(limits),
      m_read_deadline(Clock::now() + limits.stall_time) {}

ssize_t Connection::read(char* out, std::size_t size) {
  if (m_header_read < m_header.size()) {
    const std::size_t n = std::min(size, m_header.size() - m_header_read);
    std::memcpy(out, m_header.data() + m_header_read, n);
    m_header_read += n;
    return static_cast<ssize_t>(n);
  }
  for (;;) {
    const ssize_t n = ::recv(m_fd, out, size, MSG_DONTWAIT);
    if (n >= 0) return n;
    if (errno == EINTR) continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK) return -1;
    if (!wait_for(m_fd, POLLIN, until(m_read_deadline))) return -1;
  }
}

ssize_t Connection::write(const char* data, std::size_t size) {
  for (;;) {
    const ssize_t n = ::send(m_fd, data, size, MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n >= 0) return n;
    if (errno == EINTR) continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK) return -1;
    if (!wait_for(m_fd, POLLOUT, m_limits.stall_time)) return -1;
  }
}

bool Connection::readable() const {
  return m_header_read < m_header.size() || wait_for(m_fd, POLLIN, until(m_read_deadline));
}

bool Connection::writable() const { return wait_for(m_fd, POLLOUT, m_limits.stall_time); }

struct ConnectionPool::Impl {
  // A connection waiting for its next request; `requests`: how many it has carried so far.
  struct Waiting {
    int requests = 0;
    std::uint64_t order = 0;  // admission order: the lowest has waited longest
    Clock::time_point deadline;
  };
  struct Ready {
    int fd;
    std::size_t header_bytes;
    int requests;
  };

  ConnectionLimits limits;
  Handler handler;
  int epoll_fd = -1;
  int wake_fd = -1;  // an eventfd: admit() and shutdown() wake the waiting thread with it

  std::mutex mutex;  // guards the members below
  std::condition_variable work_available;
  bool stopping = false;
  std::deque<std::pair<int, int>> incoming;  // (fd, requests) admitted, not yet in epoll
  std::deque<Ready> ready;
  std::set<int> active;  // fds a worker is running a request on

  std::atomic<std::size_t> waiting_count{0};
  std::thread waiter;
  std::vector<std::thread> workers;

  Impl(const ConnectionLimits& l, Handler h) : limits(l), handler(std::move(h)) {}
  ~Impl() { shutdown(); }

  void start() {
    epoll_fd = ::epoll_create1(EPOLL_CLOEXEC);
    wake_fd = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    epoll_event ev{};
    ev.events = EPOLLIN;
    ev.data.fd = wake_fd;
    if (epoll_fd < 0 || wake_fd < 0 || ::epoll_ctl(epoll_fd, EPOLL_CTL_ADD, wake_fd, &ev) != 0) {
      throw spectral::RuntimeError(std::string("--serve: cannot create the connection poller: ") + std::strerror(errno));
    }
    waiter = std::thread([this] { wait_loop(); });
    for (int i = 0; i < limits.workers; ++i) workers.emplace_back([this] { work_loop(); });
  }

  void wake() const {
    const std::uint64_t one = 1;
    [[maybe_unused]] const auto n = ::write(wake_fd, &one, sizeof one);
  }

  void admit(int fd, int requests) {
    {
      const std::lock_guard lock(mutex);
      if (!stopping) {
        incoming.emplace_back(fd, requests);
        fd = -1;
      }
    }
    if (fd >= 0) {
      ::close(fd);
      return;
    }
    wake();
  }

  void wait_loop();
  void work_loop();
  bool run_one(const Ready& r);
  void shutdown();
};

// The waiting room: every connection that has no complete request yet, watched edge-triggered
// (woken only when new bytes arrive, so a half-sent request is not re-examined in a busy loop).
void ConnectionPool::Impl::wait_loop() {
  std::vector<char> peek(kMaxHeaderBytes + limits.max_body_bytes + 1);
  std::map<int, Waiting> waiting;
  std::uint64_t admitted = 0;
  const auto drop = [&](int fd) {
    ::epoll_ctl(epoll_fd, EPOLL_CTL_DEL, fd, nullptr);
    ::close(fd);
    waiting.erase(fd);
  };
  std::vector<epoll_event> events(64);
  for (;;) {
    std::deque<std::pair<int, int>> fresh;
    {
      const std::lock_guard lock(mutex);
      if (stopping) break;
      fresh.swap(incoming);
    }
    const auto now = Clock::now();
    for (const auto& [fd, requests] : fresh) {
      if (waiting.size() >= limits.max_waiting) {  // full: the connection waiting longest goes
        const auto oldest = std::min_element(waiting.begin(), waiting.end(),
                                             [](const auto& a, const auto& b) { return a.second.order < b.second.order; });
        drop(oldest->first);
      }
      epoll_event ev{};
      ev.events = EPOLLIN | EPOLLRDHUP | EPOLLET;  // reports bytes already there once, then each new arrival
      ev.data.fd = fd;
      if (::epoll_ctl(epoll_fd, EPOLL_CTL_ADD, fd, &ev) != 0) {
        ::close(fd);
        continue;
      }
      waiting[fd] = {requests, admitted++, now + limits.request_time};
    }
    auto next = now + milliseconds(1000);
    for (const auto& [fd, w] : waiting) next = std::min(next, w.deadline);
    waiting_count = waiting.size();
    const int n = ::epoll_wait(epoll_fd, events.data(), static_cast<int>(events.size()),
                               static_cast<int>(until(next).count()) + 1);
    for (int i = 0; i < n; ++i) {
      const int fd = events[static_cast<std::size_t>(i)].data.fd;
      if (fd == wake_fd) {
        std::uint64_t count = 0;
        [[maybe_unused]] const auto r = ::read(wake_fd, &count, sizeof count);
        continue;
      }
      const auto it = waiting.find(fd);
      if (it == waiting.end()) continue;
      const ssize_t got = ::recv(fd, peek.data(), peek.size(), MSG_PEEK | MSG_DONTWAIT);
      if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) continue;
      if (got <= 0) {  // closed by the client, or failed
        drop(fd);
        continue;
      }
      const RequestProgress p = request_progress({peek.data(), static_cast<std::size_t>(got)}, limits.max_body_bytes);
      if (!p.complete) continue;
      ::epoll_ctl(epoll_fd, EPOLL_CTL_DEL, fd, nullptr);
      const int requests = it->second.requests;
      waiting.erase(it);
      {
        const std::lock_guard lock(mutex);
        ready.push_back({fd, p.header_bytes, requests});
      }
      work_available.notify_one();
    }
    std::vector<int> late;  // no whole request in time
    const auto later = Clock::now();
    for (const auto& [fd, w] : waiting)
      if (w.deadline <= later) late.push_back(fd);
    for (const int fd : late) drop(fd);
  }
  for (const auto& entry : waiting) ::close(entry.first);
  waiting_count = 0;
}

void ConnectionPool::Impl::work_loop() {
  for (;;) {
    Ready r{};
    {
      std::unique_lock lock(mutex);
      work_available.wait(lock, [this] { return stopping || !ready.empty(); });
      if (stopping) return;
      r = ready.front();
      ready.pop_front();
      active.insert(r.fd);
    }
    const bool keep = run_one(r);
    {
      const std::lock_guard lock(mutex);
      active.erase(r.fd);
    }
    if (keep) {
      admit(r.fd, r.requests + 1);
    } else {
      ::shutdown(r.fd, SHUT_RDWR);
      ::close(r.fd);
    }
  }
}

// Takes the header off the socket (the waiting thread saw it arrive whole) and runs the handler.
bool ConnectionPool::Impl::run_one(const Ready& r) {
  std::string header(r.header_bytes, '\0');
  for (std::size_t got = 0; got < header.size();) {
    const ssize_t n = ::recv(r.fd, header.data() + got, header.size() - got, MSG_DONTWAIT);
    if (n <= 0 && !(n < 0 && errno == EINTR)) return false;
    if (n > 0) got += static_cast<std::size_t>(n);
  }
  Connection connection(r.fd, std::move(header), r.requests, limits);
  try {
    return handler(connection) && !connection.last_request();
  } catch (...) {
    return false;  // the handler answers its own errors; anything else ends the connection
  }
}

void ConnectionPool::Impl::shutdown() {
  {
    const std::lock_guard lock(mutex);
    if (stopping) return;
    stopping = true;
    for (const int fd : active) ::shutdown(fd, SHUT_RDWR);  // the running requests' I/O fails now
  }
  work_available.notify_all();
  if (wake_fd >= 0) wake();
  if (waiter.joinable()) waiter.join();
  for (std::thread& t : workers)
    if (t.joinable()) t.join();
  for (const Ready& r : ready) ::close(r.fd);
  for (const auto& entry : incoming) ::close(entry.first);
  ready.clear();
  incoming.clear();
  if (epoll_fd >= 0) ::close(epoll_fd);
  if (wake_fd >= 0) ::close(wake_fd);
  epoll_fd = wake_fd = -1;
}

ConnectionPool::ConnectionPool(const ConnectionLimits& limits, Handler handler)
    : m_impl(std::make_unique<Impl>(limits, std::move(handler))) {
  m_impl->start();
}

ConnectionPool::~ConnectionPool() = default;

void ConnectionPool::admit(int fd) { m_impl->admit(fd, 0); }

void ConnectionPool::shutdown() { m_impl->shutdown(); }

std::size_t ConnectionPool::waiting() const { return m_impl->waiting_count; }

}  // namespace prizma::relight
