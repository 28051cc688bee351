// prizma-relight --serve: routes of the live page over cpp-httplib. Every route is a fixed path; the
// page and its script come from the binary (serve_assets.h), data from the loaded session. httplib
// accepts connections and parses and answers requests; a ConnectionPool holds the connections
// (connection_pool.h), PageAccess decides who may ask (page_access.h), SaveFolder where Save writes.
#include "prizma/relight/serve.h"

#include <arpa/inet.h>
#include <httplib.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <initializer_list>
#include <map>
#include <mutex>
#include <system_error>
#include <thread>

#include "page_transport.h"
#include "prizma/relight/canvas_colour_space.h"
#include "prizma/relight/connection_pool.h"
#include "prizma/relight/save_folder.h"
#include "prizma/relight/serve_state.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectrum_spec.h"
#include "prizma/spectral/version.h"
#include "serve_assets.h"

namespace prizma::relight {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using spectral::InputError;

// Request bodies: the API takes none (its parameters are in the URL).
constexpr std::size_t kMaxBodyBytes = std::size_t{1} << 16;

void send_json(httplib::Response& res, const json& body, int status = 200) {
  res.status = status;
  res.set_content(body.dump(), "application/json");
}

// An integer request parameter within [lo, hi]; InputError naming it otherwise.
int int_param(const httplib::Request& req, const std::string& key, int lo, int hi) {
  if (!req.has_param(key)) throw InputError(key, "missing");
  const std::string v = req.get_param_value(key);
  int out = 0;
  const auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), out);
  if (v.empty() || ec != std::errc() || ptr != v.data() + v.size() || out < lo || out > hi) {
    throw InputError(key, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], not \"" +
                              v + "\"");
  }
  return out;
}

json vec3(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

// A socket's own (local) or peer address as text and port.
void address_of(int fd, bool peer, std::string& ip, int& port) {
  sockaddr_storage addr{};
  socklen_t len = sizeof addr;
  auto* sa = reinterpret_cast<sockaddr*>(&addr);
  ip.clear();
  port = 0;
  if ((peer ? ::getpeername(fd, sa, &len) : ::getsockname(fd, sa, &len)) != 0) return;
  char text[INET6_ADDRSTRLEN] = {};
  if (addr.ss_family == AF_INET) {
    const auto* a = reinterpret_cast<const sockaddr_in*>(&addr);
    ::inet_ntop(AF_INET, &a->sin_addr, text, sizeof text);
    port = ntohs(a->sin_port);
  } else if (addr.ss_family == AF_INET6) {
    const auto* a = reinterpret_cast<const sockaddr_in6*>(&addr);
    ::inet_ntop(AF_INET6, &a->sin6_addr, text, sizeof text);
    port = ntohs(a->sin6_port);
  }
  ip = text;
}

// One request of a pooled connection, as httplib reads and answers it.
class ConnectionStream final : public httplib::Stream {
 public:
  explicit ConnectionStream(Connection& c) : m_c(c) {}
  bool is_readable() const override { return m_c.readable(); }
  bool is_writable() const override { return m_c.writable(); }
  ssize_t read(char* ptr, std::size_t size) override { return m_c.read(ptr, size); }
  ssize_t write(const char* ptr, std::size_t size) override { return m_c.write(ptr, size); }
  using httplib::Stream::write;
  void get_remote_ip_and_port(std::string& ip, int& port) const override { address_of(m_c.fd(), true, ip, port); }
  void get_local_ip_and_port(std::string& ip, int& port) const override { address_of(m_c.fd(), false, ip, port); }
  socket_t socket() const override { return m_c.fd(); }

 private:
  Connection& m_c;
};

// httplib's server with every accepted connection handed to a ConnectionPool instead of httplib's
// thread pool (where each idle or slow connection held one of 8 threads until its timeout).
// process_and_close_socket is httplib's (private, virtual) per-connection entry point.
class PooledServer final : public httplib::Server {
 public:
  ConnectionPool* pool = nullptr;

  // Reads and answers one request; false when the connection cannot carry another.
  bool serve_request(httplib::Stream& stream, bool last) {
    bool closed = false;
    return process_request(stream, last, closed, nullptr) && !closed;
  }

 private:
  bool process_and_close_socket(socket_t sock) override {
    pool->admit(sock);
    return true;
  }
};

// The task queue httplib's listener gives each accepted socket to: passed straight on (to
// process_and_close_socket, then ConnectionPool::admit, which never blocks); the pool is shut when
// the listener stops.
class PoolQueue final : public httplib::TaskQueue {
 public:
  explicit PoolQueue(ConnectionPool& pool) : m_pool(pool) {}
  void enqueue(std::function<void()> fn) override { fn(); }
  void shutdown() override { m_pool.shutdown(); }

 private:
  ConnectionPool& m_pool;
};

}  // namespace

struct RelightServer::Impl {
  RelightSession& session;
  ServeOptions opts;
  RelightSettings base;  // the command line's settings: the page's starting state
  SaveFolder save_folder;
  PageAccess access;
  PooledServer server;
  std::mutex log_mutex;
  int port = 0;
  std::mutex mutex;  // guards session and caches (handlers run on the pool's workers)
  std::map<std::string, std::string> display_cache;
  PageTransport transport;  // the texture layers and their weights (bins or coefficients)
  // Last: destroyed first, so its workers have stopped before anything their handlers use goes.
  std::unique_ptr<ConnectionPool> pool;

  Impl(RelightSession& s, const ServeOptions& o)
      : session(s), opts(o), base(s.settings()), save_folder(o.save_dir, s.source()),
        access(PageAccess::new_token(), o.bind, 0), transport(s) {}

  // Refuses (403) a request PageAccess refuses, naming why; reported on opts.log too.
  httplib::Server::HandlerResponse check_access(const httplib::Request& req, httplib::Response& res) {
    const std::string why = access.refusal(req.path, {req.get_header_value("Host"), req.get_header_value("Origin"),
                                                      req.get_header_value("Sec-Fetch-Site"),
                                                      req.get_header_value(PageAccess::kTokenHeader)});
    if (why.empty()) return httplib::Server::HandlerResponse::Unhandled;
    send_json(res, {{"error", why}}, 403);
    if (opts.log) {
      const std::lock_guard lock(log_mutex);
      *opts.log << "prizma-relight: refused " << req.method << " " << req.path << ": " << why << std::endl;
    }
    return httplib::Server::HandlerResponse::Handled;
  }

  // The request's state keys (light.*, exposure, cmf, display, adapt): every parameter not in `own`.
  RelightSettings settings_of(const httplib::Request& req, std::initializer_list<const char*> own) const {
    StateParams params;
    for (const auto& param : req.params) {
      const std::string& key = param.first;
      if (std::find_if(own.begin(), own.end(), [&key](const char* k) { return key == k; }) == own.end()) {
        params.emplace_back(key, param.second);
      }
    }
    return settings_from_state(params, session, base);
  }

  // Applies the request's state to the session and checks that its lights and display are usable.
  void apply_state(const httplib::Request& req, std::initializer_list<const char*> own) {
    RelightSettings s = settings_of(req, own);
    for (std::size_t l = 0; l < s.lights.size(); ++l) {
      // A recorded default that did not parse here (a CSV from another machine) cannot be drawn.
      const LightSpec& d = session.default_lights()[l];
      if (s.lights[l].off && d.off && s.lights[l].text == d.text && d.text != "off") {
        parse_light_spec(d.text, {"light." + session.light_names()[l], {}});
      }
    }
    session.apply(std::move(s));
    session.display();  // throws InputError for an unknown display
  }

  json info() const {
    const auto& img = session.image();
    json lights = json::array();
    for (std::size_t l = 0; l < session.light_names().size(); ++l) {
      lights.push_back({{"name", session.light_names()[l]},
                        {"default", session.default_lights()[l].text},
                        {"spec", base.lights[l].text}});
    }
    // Per display of the config, the canvas colour space that shows it (null: none; the page then
    // says so and shows another display) and what it encodes.
    json spaces = json::object();
    for (const std::string& name : spectral::DisplayTransform(display_options("")).displays()) {
      const CanvasColourSpace cs = canvas_colour_space(spectral::DisplayTransform(display_options(name)), name);
      spaces[name] = {{"canvas", cs.canvas.empty() ? json(nullptr) : json(cs.canvas)}, {"encoding", cs.encoding}};
    }
    json out = {{"source", fs::path(session.source()).filename().string()},
                {"version", spectral::prizma_version()},
                {"width", img.width},
                {"height", img.height},
                {"bins", img.bins.edges_nm()},
                {"lights", lights},
                {"state", state_string(base, session)},
                {"displays", spectral::DisplayTransform(display_options("")).displays()},
                {"displaySpaces", spaces},
                {"observers", {"1931", "1964", "2012-2", "2012-10"}},
                {"spectra", spectral::named_illuminants()}};
    // A denoised file says so in the page's title (null: the raw Monte Carlo means).
    const std::string denoised = spectral::denoised_summary(img.info);
    out["denoised"] = denoised.empty() ? json(nullptr) : json(denoised);
    out.update(transport.describe());
    return out;
  }

  // The lights' bin averages times their scales, for the page's plot.
  json spectra(const RelightSettings& s) const {
    json lights = json::array();
    for (std::size_t l = 0; l < s.lights.size(); ++l) {
      const LightSpec& light = s.lights[l];
      std::vector<double> v(static_cast<std::size_t>(session.image().bins.size()), 0.0);
      if (!light.off) {
        v = light.spectrum.bin_averages(session.image().bins);
        for (double& x : v) x *= light.scale;
      }
      lights.push_back({{"name", session.light_names()[l]}, {"spec", light.text}, {"values", v}});
    }
    return {{"lights", lights}};
  }

  // The command line's OCIO config with display `name` and its default view (empty: the starting display).
  spectral::DisplayOptions display_options(const std::string& name) const {
    spectral::DisplayOptions d = base.output.display;
    d.colour_space.clear();
    if (!name.empty()) {
      d.display = name;
      d.view.clear();
    }
    return d;
  }

  std::string display_shader(const std::string& name) {
    if (const auto it = display_cache.find(name); it != display_cache.end()) return it->second;
    const spectral::DisplayShader shader = spectral::DisplayTransform(display_options(name)).gpu_shader();
    json uniforms = json::array(), textures = json::array();
    for (const auto& u : shader.uniforms) uniforms.push_back({{"name", u.name}, {"type", u.type}, {"values", u.values}});
    for (const auto& t : shader.textures) {
      textures.push_back({{"name", t.name}, {"sampler", t.sampler}, {"width", t.width}, {"height", t.height},
                          {"depth", t.depth}, {"channels", t.channels}, {"linear", t.linear}, {"values", t.values}});
    }
    const json body = {{"display", name}, {"glsl", shader.glsl}, {"function", shader.function_name},
                       {"uniforms", uniforms}, {"textures", textures}};
    return display_cache[name] = body.dump();
  }

  // Runs a handler, mapping InputError to 400 and any other failure to 500, with a JSON message.
  template <class F>
  httplib::Server::Handler guarded(F f) {
    return [f](const httplib::Request& req, httplib::Response& res) {
      try {
        f(req, res);
      } catch (const InputError& e) {
        send_json(res, {{"error", e.what()}}, 400);
      } catch (const std::exception& e) {
        send_json(res, {{"error", e.what()}}, 500);
      }
    };
  }

  void routes();
};

// long on purpose: the route table: one short handler per URL, listed together so the API reads in one place.
void RelightServer::Impl::routes() {
  const ConnectionLimits limits;
  server.set_payload_max_length(kMaxBodyBytes);
  // What the Keep-Alive header announces; the pool enforces it.
  server.set_keep_alive_timeout(std::chrono::duration_cast<std::chrono::seconds>(limits.request_time).count());
  server.set_keep_alive_max_count(static_cast<std::size_t>(limits.max_requests));
  // Not listed, so not allowed: frames (no page may embed this one), plugins, forms' targets elsewhere.
  server.set_default_headers({{"Cache-Control", "no-store"},
                              {"X-Content-Type-Options", "nosniff"},
                              {"Referrer-Policy", "no-referrer"},
                              {"Content-Security-Policy",
                               "default-src 'self'; style-src 'self' 'unsafe-inline'; object-src 'none'; "
                               "base-uri 'none'; form-action 'none'; frame-ancestors 'none'"}});
  server.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    return check_access(req, res);
  });
  server.set_error_handler(httplib::Server::HandlerWithResponse([](const httplib::Request&, httplib::Response& res) {
    if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
    send_json(res, {{"error", "HTTP status " + std::to_string(res.status)}}, res.status);
    return httplib::Server::HandlerResponse::Handled;
  }));

  for (const char* page : {"/", "/index\\.html"}) {
    server.Get(page, [](const httplib::Request&, httplib::Response& res) {
      res.set_content(std::string(detail::web_asset("index.html")), "text/html; charset=utf-8");
    });
  }
  for (const auto& [route, script] : {std::pair{"/app\\.js", "app.js"}, std::pair{"/state\\.js", "state.js"},
                                      std::pair{"/plots\\.js", "plots.js"}, std::pair{"/gpu\\.js", "gpu.js"}}) {
    server.Get(route, [script = script](const httplib::Request&, httplib::Response& res) {
      res.set_content(std::string(detail::web_asset(script)), "text/javascript; charset=utf-8");
    });
  }
  server.Get("/api/info", guarded([this](const httplib::Request&, httplib::Response& res) {
    const std::lock_guard lock(mutex);
    send_json(res, info());
  }));
  server.Get("/api/transport", guarded([this](const httplib::Request& req, httplib::Response& res) {
    const auto& img = session.image();
    const int l = int_param(req, "light", 0, static_cast<int>(img.lights.size()) - 1);
    const int g = int_param(req, "group", 0, transport.groups() + transport.reradiation_groups() - 1);
    const std::string type = req.has_param("type") ? req.get_param_value("type") : "f32";
    if (type != "f32" && type != "f16") throw InputError("type", "expected f32 or f16, not \"" + type + "\"");
    const spectral::Observer cmf =
        req.has_param("cmf") ? spectral::parse_observer(req.get_param_value("cmf"), "cmf") : base.relight.cmf;
    res.set_content(transport.layer(l, g, type == "f16", cmf), "application/octet-stream");
  }));
  server.Get("/api/weights", guarded([this](const httplib::Request& req, httplib::Response& res) {
    const std::lock_guard lock(mutex);
    apply_state(req, {});
    json body = transport.weights(session.settings());
    body["state"] = state_string(session.settings(), session);
    send_json(res, body);
  }));
  server.Get("/api/spectra", guarded([this](const httplib::Request& req, httplib::Response& res) {
    const std::lock_guard lock(mutex);
    send_json(res, spectra(settings_of(req, {})));
  }));
  server.Get("/api/display", guarded([this](const httplib::Request& req, httplib::Response& res) {
    if (!req.has_param("name")) throw InputError("name", "missing");
    const std::lock_guard lock(mutex);
    res.set_content(display_shader(req.get_param_value("name")), "application/json");
  }));
  server.Get("/api/probe", guarded([this](const httplib::Request& req, httplib::Response& res) {
    const std::lock_guard lock(mutex);
    const int x = int_param(req, "x", 0, session.image().width - 1);
    const int y = int_param(req, "y", 0, session.image().height - 1);
    apply_state(req, {"x", "y"});
    const ProbeResult p = session.probe(x, y);
    json bins = json::array();  // in the file's light order
    const auto& pairs_held = session.image().reradiation;
    for (std::size_t l = 0; l < p.bins.size(); ++l) {
      json entry = {{"name", session.light_names()[l]}, {"bins", p.bins[l]}};
      if (const CompressedTransport* c = session.coefficients()) {  // what the page relights: B·c
        const Eigen::VectorXf t = reconstructed_spectrum(c->lights[l], static_cast<std::size_t>(y) * session.image().width +
                                                                             static_cast<std::size_t>(x));
        entry["coefficientBins"] = std::vector<float>(t.data(), t.data() + t.size());
      }
      if (!p.reradiation.empty()) {  // bispectral: the pixel's off-diagonal M[out][in], as [in, out, value]
        json pairs = json::array();
        for (std::size_t q = 0; q < pairs_held.size(); ++q)
          pairs.push_back({pairs_held[q].in, pairs_held[q].out, p.reradiation[l][q]});
        entry["pairs"] = std::move(pairs);
      }
      bins.push_back(std::move(entry));
    }
    send_json(res, {{"x", x}, {"y", y}, {"bins", bins}, {"xyz", vec3(p.xyz)}, {"lab", vec3(p.lab)},
                    {"srgb", vec3(p.srgb)}});
  }));
  server.Get("/api/compare", guarded([this](const httplib::Request& req, httplib::Response& res) {
    const std::lock_guard lock(mutex);
    const int w = session.image().width - 1, h = session.image().height - 1;
    const int x1 = int_param(req, "x1", 0, w), y1 = int_param(req, "y1", 0, h);
    const int x2 = int_param(req, "x2", 0, w), y2 = int_param(req, "y2", 0, h);
    apply_state(req, {"x1", "y1", "x2", "y2"});
    const CompareResult c = session.compare(x1, y1, x2, y2);
    send_json(res, {{"xyz1", vec3(c.xyz1)}, {"xyz2", vec3(c.xyz2)}, {"lab1", vec3(c.lab1)}, {"lab2", vec3(c.lab2)},
                    {"dE00", c.delta_e2000}});
  }));
  server.Post("/api/save", guarded([this](const httplib::Request& req, httplib::Response& res) {
    if (!req.has_param("file")) throw InputError("file", "missing");
    const std::string name = req.get_param_value("file");
    const std::lock_guard lock(mutex);
    apply_state(req, {"file"});
    const fs::path path = save_folder.save(name, [this](const fs::path& p) { session.save(p, "file"); });
    send_json(res, {{"file", name}, {"path", path.string()}, {"state", state_string(session.settings(), session)}});
  }));
  pool = std::make_unique<ConnectionPool>(limits, [this](Connection& c) {
    ConnectionStream stream(c);
    return server.serve_request(stream, c.last_request());
  });
  server.pool = pool.get();
  server.new_task_queue = [this] { return new PoolQueue(*pool); };
}

RelightServer::RelightServer(RelightSession& session, const ServeOptions& opts) {
  if (opts.port < 0 || opts.port > 65535) {
    throw InputError("--port", "must be in [0, 65535], not " + std::to_string(opts.port));
  }
  m_impl = std::make_unique<Impl>(session, opts);  // checks --save-dir
  session.display();  // the starting display must exist before the page asks for it
  m_impl->routes();
  // httplib's default socket options set SO_REUSEPORT, with which a second server on the same port
  // starts and the kernel shares the connections between the two: SO_REUSEADDR alone (a port in
  // TIME_WAIT may be reused, one that is listened on may not).
  m_impl->server.set_socket_options([](socket_t sock) {
    const int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  if (opts.port == 0) {
    m_impl->port = m_impl->server.bind_to_any_port(opts.bind);
  } else if (m_impl->server.bind_to_port(opts.bind, opts.port)) {
    m_impl->port = opts.port;
  } else {
    m_impl->port = -1;
  }
  if (m_impl->port <= 0) {
    throw InputError("--bind " + opts.bind + " --port " + std::to_string(opts.port),
                     "cannot listen there (address not local, or port in use)");
  }
  m_impl->access = PageAccess(m_impl->access.token(), opts.bind, m_impl->port);
}

RelightServer::~RelightServer() { stop(); }

int RelightServer::port() const { return m_impl->port; }

std::string RelightServer::url() const {
  const std::string& host = m_impl->opts.bind;
  const bool v6 = host.find(':') != std::string::npos;
  return "http://" + (v6 ? "[" + host + "]" : host) + ":" + std::to_string(m_impl->port) + "/#token=" +
         m_impl->access.token();
}

void RelightServer::run() {
  if (!m_impl->server.listen_after_bind() && m_impl->server.is_running()) {
    throw spectral::RuntimeError("server on " + url() + " failed");
  }
}

void RelightServer::stop() { m_impl->server.stop(); }

namespace {

// SIGINT/SIGTERM → one byte down this pipe (write is async-signal-safe); a watcher thread reads it
// and stops the server. Works whichever thread the signal lands on (OpenEXR's and TBB's included).
int g_stop_pipe[2] = {-1, -1};

extern "C" void on_stop_signal(int) {
  const char byte = 1;
  [[maybe_unused]] const auto n = ::write(g_stop_pipe[1], &byte, 1);
}

}  // namespace

void serve_until_signal(RelightServer& server, const std::function<void()>& on_ready) {
  if (::pipe(g_stop_pipe) != 0) throw spectral::RuntimeError("--serve: cannot create a pipe for signals");
  struct sigaction action{}, old_int{}, old_term{};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  ::sigaction(SIGINT, &action, &old_int);
  ::sigaction(SIGTERM, &action, &old_term);
  // httplib's stop() does nothing before listening has begun: repeat it until run() has returned.
  std::atomic<bool> finished{false};
  std::thread watcher([&server, &finished] {
    char byte = 0;
    while (::read(g_stop_pipe[0], &byte, 1) < 0 && errno == EINTR) {
    }
    while (!finished) {
      server.stop();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  });
  std::exception_ptr failure;
  try {
    if (on_ready) on_ready();
    server.run();
  } catch (...) {
    failure = std::current_exception();
  }
  finished = true;
  on_stop_signal(0);  // the server ended on its own: release the watcher
  watcher.join();
  ::sigaction(SIGINT, &old_int, nullptr);
  ::sigaction(SIGTERM, &old_term, nullptr);
  ::close(g_stop_pipe[0]);
  ::close(g_stop_pipe[1]);
  g_stop_pipe[0] = g_stop_pipe[1] = -1;
  if (failure) std::rethrow_exception(failure);
}

}  // namespace prizma::relight
