#pragma once
// The connections of the live page's server (prizma-relight --serve). Every open connection waits in
// one epoll thread until a whole request has arrived (its header, and a declared body up to
// ConnectionLimits::max_body_bytes); only then does one of a few worker threads run it. So idle
// keep-alive connections and slow ones (a header trickled byte by byte: "slowloris") hold no worker,
// the page keeps answering however many of them are open (up to max_waiting, past which the one
// waiting longest is closed), and shutdown() ends every connection at once: the server stops in
// milliseconds whatever its clients do. No HTTP parsing beyond finding where a request ends; the
// worker's handler (cpp-httplib's request processing, serve.cpp) does the rest.
#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

namespace prizma::relight {

struct ConnectionLimits {
  int workers = 8;                // threads that run complete requests
  std::size_t max_waiting = 256;  // connections waiting for a request; a new one past this closes the oldest
  // A whole request must arrive within this time once its connection starts waiting (a new
  // connection, or one kept alive after its previous answer); otherwise the connection is closed.
  std::chrono::milliseconds request_time{10000};
  // A worker's read or write that makes no progress for this long fails (a client that stops reading).
  std::chrono::milliseconds stall_time{10000};
  std::size_t max_body_bytes = 65536;  // larger declared bodies go to a worker at once, to be refused
  int max_requests = 100;              // requests served on one connection, then it is closed
};

// Whether the bytes received so far on a connection hold a whole request: `complete` when the header
// has ended ("\r\n\r\n") and its Content-Length body (up to max_body_bytes) is there too, or when the
// request is malformed or too long for waiting to help (a header past 16 KiB, a body past the limit,
// a Transfer-Encoding, an Expect: 100-continue: the worker answers, refuses or bounds these). `header_bytes`: the header's length with
// its blank line when it has ended, else 0.
struct RequestProgress {
  bool complete = false;
  std::size_t header_bytes = 0;
};
RequestProgress request_progress(std::string_view received, std::size_t max_body_bytes);

// One connection as a worker sees it while it runs one request: reads return the header the waiting
// thread saw complete, then the socket's bytes; reads fail once stall_time has passed since the
// request was handed over, writes when the client accepts nothing for stall_time.
class Connection {
 public:
  Connection(int fd, std::string header, int requests_before, const ConnectionLimits& limits);
  ssize_t read(char* out, std::size_t size);
  ssize_t write(const char* data, std::size_t size);
  bool readable() const;  // bytes can be read now, or arrive before the read deadline
  bool writable() const;  // the socket accepts bytes within stall_time
  int fd() const { return m_fd; }
  // The last request this connection may carry (ConnectionLimits::max_requests): answer "close".
  bool last_request() const { return m_requests_before + 1 >= m_limits.max_requests; }

 private:
  int m_fd;
  std::string m_header;
  std::size_t m_header_read = 0;
  int m_requests_before;
  const ConnectionLimits& m_limits;
  std::chrono::steady_clock::time_point m_read_deadline;
};

class ConnectionPool {
 public:
  // Runs one request of `connection`; returns true to keep the connection open for another.
  using Handler = std::function<bool(Connection& connection)>;

  // Starts the waiting thread and the workers. Throws RuntimeError when they cannot be created.
  ConnectionPool(const ConnectionLimits& limits, Handler handler);
  ~ConnectionPool();  // shutdown()
  ConnectionPool(const ConnectionPool&) = delete;
  ConnectionPool& operator=(const ConnectionPool&) = delete;

  // Takes an accepted socket (the pool closes it). Never blocks; after shutdown() closes it at once.
  void admit(int fd);
  // Closes every connection (those in a worker are shut down, so their reads and writes fail at
  // once), waits for the running handlers to return and joins the threads. Idempotent.
  void shutdown();
  // Connections waiting for a request now (tests).
  std::size_t waiting() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

}  // namespace prizma::relight
