#pragma once
// prizma-relight --serve: a small HTTP server (cpp-httplib) for the live relighting page. It serves
// the page (embedded in the binary at build time) and the data of one spectral file: bins, lights,
// transport layers as binary textures, the exact relight weight matrices and the OCIO display
// transform as GLSL. No request path reaches the file system; "save" writes only plain file names
// inside ServeOptions::save_dir (save_folder.h). Only the page opened with the URL the server prints
// may use the data (page_access.h). Endpoints: docs/relight.md, "Live page".
#include <filesystem>
#include <functional>
#include <memory>
#include <ostream>
#include <string>

#include "prizma/relight/page_access.h"
#include "prizma/relight/relight_session.h"

namespace prizma::relight {

struct ServeOptions {
  std::string bind = "127.0.0.1";     // address to listen on
  int port = 0;                       // 0: a free port chosen by the system
  std::filesystem::path save_dir = ".";  // where "save" writes (existing, writable folder)
  std::ostream* log = nullptr;           // when set, each refused request is reported there (--verbose)
};

class RelightServer {
 public:
  // Binds the socket (so port() is known before run()) and draws the page's secret. The session's
  // current settings are the page's starting state. Throws InputError for a bad save folder or
  // port, and when the address cannot be listened on (not local, or the port in use).
  RelightServer(RelightSession& session, const ServeOptions& opts);
  ~RelightServer();
  RelightServer(const RelightServer&) = delete;
  RelightServer& operator=(const RelightServer&) = delete;

  int port() const;
  // The page's whole URL, its secret included: "http://ADDR:PORT/#token=SECRET" (IPv6 addresses in
  // brackets). Whoever has it can use the page.
  std::string url() const;
  // Serves until stop() is called (from any thread).
  void run();
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

// Runs the server until SIGINT or SIGTERM arrives, then stops it cleanly (handlers for the two
// signals are installed while it runs, the previous ones restored after). `on_ready` runs once the
// handlers are in place (prizma-relight prints the URL there, so a signal sent after it is never lost).
void serve_until_signal(RelightServer& server, const std::function<void()>& on_ready = {});

}  // namespace prizma::relight
