// The live page's connections (connection_pool.h): where a request ends, and a pool whose idle or
// half-sent connections never hold a worker and which closes everything at shutdown. Plain socket
// pairs stand in for TCP connections (the e2e test, relight.live.server, uses real ones).
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include "prizma/relight/connection_pool.h"

namespace prizma::relight {
namespace {

using namespace std::chrono_literals;

TEST(RequestProgress, WaitsForTheBlankLineThatEndsTheHeader) {
  EXPECT_FALSE(request_progress("GET / HTTP/1.1\r\nHost: a\r\n", 100).complete);
  const RequestProgress p = request_progress("GET / HTTP/1.1\r\nHost: a\r\n\r\n", 100);
  EXPECT_TRUE(p.complete);
  EXPECT_EQ(p.header_bytes, 27u);
  EXPECT_TRUE(request_progress("GET / HTTP/1.1\r\n\r\n", 100).complete);
}

TEST(RequestProgress, WaitsForADeclaredBodyUpToTheLimit) {
  const std::string head = "POST /api/save HTTP/1.1\r\ncontent-LENGTH:  5 \r\n\r\n";
  EXPECT_FALSE(request_progress(head + "abcd", 100).complete);
  EXPECT_TRUE(request_progress(head + "abcde", 100).complete);
  EXPECT_EQ(request_progress(head + "abcde", 100).header_bytes, head.size());
  // Past the limit, malformed, or chunked: the worker takes it at once (and refuses or bounds it).
  EXPECT_TRUE(request_progress("POST / HTTP/1.1\r\nContent-Length: 101\r\n\r\n", 100).complete);
  EXPECT_TRUE(request_progress("POST / HTTP/1.1\r\nContent-Length: 5x\r\n\r\n", 100).complete);
  EXPECT_TRUE(request_progress("POST / HTTP/1.1\r\nContent-Length: 99999999999999999999999\r\n\r\n", 100).complete);
  EXPECT_TRUE(request_progress("POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n", 100).complete);
  // A client that sends its body only after "100 Continue" would wait for the pool, and it for the body.
  EXPECT_TRUE(request_progress("POST / HTTP/1.1\r\nContent-Length: 5\r\nExpect: 100-continue\r\n\r\n", 100).complete);
}

TEST(RequestProgress, GivesUpWaitingForAnOverlongHeader) {
  EXPECT_FALSE(request_progress("GET /" + std::string(16000, 'a'), 100).complete);
  const RequestProgress p = request_progress("GET /" + std::string(16384, 'a'), 100);
  EXPECT_TRUE(p.complete);
  EXPECT_EQ(p.header_bytes, 0u);
}

// A connected pair of stream sockets: [0] goes to the pool, [1] is the client.
std::vector<int> socket_pair() {
  int fds[2];
  EXPECT_EQ(::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds), 0);
  return {fds[0], fds[1]};
}

// Reads what the pool answers (until it closes, or up to `bytes`); "" when nothing comes within 10 s.
std::string answer(int fd, std::size_t bytes = 64) {
  std::string out;
  char buf[256];
  while (out.size() < bytes) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 10000) != 1) break;
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n <= 0) break;
    out.append(buf, static_cast<std::size_t>(n));
  }
  return out;
}

// A handler that reads the header and answers "ok <requests so far>".
ConnectionPool::Handler echo(std::atomic<int>& served) {
  return [&served](Connection& c) {
    char buf[256];
    std::string got;
    while (got.find("\r\n\r\n") == std::string::npos) {
      const ssize_t n = c.read(buf, sizeof buf);
      if (n <= 0) return false;
      got.append(buf, static_cast<std::size_t>(n));
    }
    const std::string reply = "ok " + std::to_string(++served) + "\n";
    return c.write(reply.data(), reply.size()) == static_cast<ssize_t>(reply.size());
  };
}

TEST(ConnectionPool, IdleAndHalfSentConnectionsHoldNoWorker) {
  ConnectionLimits limits;
  limits.workers = 1;  // one worker: any connection that held it would stop the pool
  std::atomic<int> served{0};
  ConnectionPool pool(limits, echo(served));
  std::vector<std::vector<int>> idle, slow;
  for (int i = 0; i < 64; ++i) {
    idle.push_back(socket_pair());
    pool.admit(idle.back()[0]);
    slow.push_back(socket_pair());
    pool.admit(slow.back()[0]);
    ASSERT_EQ(::write(slow.back()[1], "GET / HTTP/1.1\r\nX-Slow: ", 24), 24);  // never finished
  }
  for (int request = 1; request <= 3; ++request) {
    const std::vector<int> page = socket_pair();
    pool.admit(page[0]);
    ASSERT_EQ(::write(page[1], "GET / HTTP/1.1\r\n\r\n", 18), 18);
    EXPECT_EQ(answer(page[1], 5), "ok " + std::to_string(request) + "\n");
    ::close(page[1]);
  }
  pool.shutdown();
  for (const auto& s : idle) ::close(s[1]);
  for (const auto& s : slow) ::close(s[1]);
}

TEST(ConnectionPool, KeepsAConnectionForTheNextRequest) {
  std::atomic<int> served{0};
  ConnectionPool pool(ConnectionLimits{}, echo(served));
  const std::vector<int> c = socket_pair();
  pool.admit(c[0]);
  for (int request = 1; request <= 3; ++request) {
    ASSERT_EQ(::write(c[1], "GET / HTTP/1.1\r\n\r\n", 18), 18);
    EXPECT_EQ(answer(c[1], 5), "ok " + std::to_string(request) + "\n");
  }
  ::close(c[1]);
}

TEST(ConnectionPool, ClosesAConnectionWithoutAWholeRequestInTime) {
  ConnectionLimits limits;
  limits.request_time = 200ms;
  std::atomic<int> served{0};
  ConnectionPool pool(limits, echo(served));
  const std::vector<int> c = socket_pair();
  pool.admit(c[0]);
  ASSERT_EQ(::write(c[1], "GET / HT", 8), 8);
  EXPECT_EQ(answer(c[1]), "");  // closed (end of file), not answered
  EXPECT_EQ(served, 0);
  ::close(c[1]);
}

TEST(ConnectionPool, PastItsLimitClosesTheConnectionWaitingLongest) {
  ConnectionLimits limits;
  limits.max_waiting = 4;
  std::atomic<int> served{0};
  ConnectionPool pool(limits, echo(served));
  std::vector<std::vector<int>> c;
  for (int i = 0; i < 6; ++i) {
    c.push_back(socket_pair());
    pool.admit(c.back()[0]);
    while (pool.waiting() < std::min<std::size_t>(static_cast<std::size_t>(i) + 1, 4)) std::this_thread::sleep_for(1ms);
  }
  EXPECT_EQ(answer(c[0][1]), "");  // the two oldest are closed
  EXPECT_EQ(answer(c[1][1]), "");
  ASSERT_EQ(::write(c[5][1], "GET / HTTP/1.1\r\n\r\n", 18), 18);  // the newest is served
  EXPECT_EQ(answer(c[5][1], 5), "ok 1\n");
  for (const auto& s : c) ::close(s[1]);
}

TEST(ConnectionPool, ShutdownEndsARequestBlockedOnItsClient) {
  std::promise<ssize_t> read_result;
  std::atomic<bool> reading{false};
  ConnectionPool pool(ConnectionLimits{}, [&](Connection& c) {
    char buf[64];
    for (int got = 0; got < 18 && c.read(buf, 1) == 1; ++got) {  // the whole header
    }
    reading = true;
    read_result.set_value(c.read(buf, sizeof buf));  // the declared body never comes
    return false;
  });
  const std::vector<int> c = socket_pair();
  pool.admit(c[0]);
  ASSERT_EQ(::write(c[1], "GET / HTTP/1.1\r\n\r\n", 18), 18);
  while (!reading) std::this_thread::sleep_for(1ms);
  // stall_time is 10 s: without shutting the socket down, the read would wait that long.
  auto stopped = std::async(std::launch::async, [&] { pool.shutdown(); });
  ASSERT_EQ(stopped.wait_for(5s), std::future_status::ready);
  EXPECT_LE(read_result.get_future().get(), 0);
  EXPECT_EQ(answer(c[1]), "");
  ::close(c[1]);
}

TEST(ConnectionPool, AdmitAfterShutdownClosesTheSocket) {
  std::atomic<int> served{0};
  ConnectionPool pool(ConnectionLimits{}, echo(served));
  pool.shutdown();
  const std::vector<int> c = socket_pair();
  pool.admit(c[0]);
  EXPECT_EQ(answer(c[1]), "");
  ::close(c[1]);
}

}  // namespace
}  // namespace prizma::relight
