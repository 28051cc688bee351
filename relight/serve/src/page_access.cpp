// Who may use the live page: Host, origin and the run's secret (page_access.h).
#include "prizma/relight/page_access.h"

#include <arpa/inet.h>
#include <sys/random.h>

#include <cerrno>
#include <cstring>

#include "prizma/spectral/error.h"

namespace prizma::relight {

bool is_loopback_address(const std::string& address) {
  if (address == "localhost" || address == "::1") return true;
  in_addr v4{};
  if (::inet_pton(AF_INET, address.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  return false;
}

bool same_secret(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;  // the length is no secret: every token has 32 digits
  volatile unsigned char differ = 0;       // volatile: no early exit at the first difference
  for (std::size_t i = 0; i < a.size(); ++i) differ = differ | static_cast<unsigned char>(a[i] ^ b[i]);
  return differ == 0;
}

std::string PageAccess::new_token() {
  unsigned char bytes[16];
  for (std::size_t got = 0; got < sizeof bytes;) {
    const ssize_t n = ::getrandom(bytes + got, sizeof bytes - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw spectral::RuntimeError(std::string("--serve: cannot draw the page's secret (getrandom: ") +
                                            std::strerror(errno) + ")");
    got += static_cast<std::size_t>(n);
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string token;
  for (const unsigned char b : bytes) {
    token += kHex[b >> 4];
    token += kHex[b & 15];
  }
  return token;
}

PageAccess::PageAccess(std::string token, std::string bind, int port)
    : m_token(std::move(token)), m_bind(std::move(bind)), m_port(port) {}

std::string PageAccess::refusal(std::string_view path, const RequestOrigin& r) const {
  // Bound to loopback, only requests that name a loopback host (no DNS rebinding from other sites).
  if (is_loopback_address(m_bind)) {
    const std::string p = ":" + std::to_string(m_port);
    bool ours = false;
    for (const char* h : {"127.0.0.1", "localhost", "[::1]"}) ours = ours || r.host == h + p;
    if (!ours) return "Host \"" + r.host + "\" is not this server's loopback address";
  }
  if (path.substr(0, 5) != "/api/") return {};
  // What browsers say of a request sent by another page (Fetch Metadata, then Origin).
  if (!r.fetch_site.empty() && r.fetch_site != "same-origin" && r.fetch_site != "none") {
    return "a request from another page (Sec-Fetch-Site: " + r.fetch_site + ") may not use this server";
  }
  const std::string own = "http://" + r.host;
  if (!r.origin.empty() && r.origin != own) {
    return "a request from another page (Origin " + r.origin + ", this page is " + own + ") may not use this server";
  }
  if (r.token.empty()) {
    return std::string("no access key (") + kTokenHeader +
           "): open the page with the whole URL prizma-relight printed, #token=… included";
  }
  if (!same_secret(r.token, m_token)) {
    return std::string("wrong access key (") + kTokenHeader +
           "): open the page with the URL this prizma-relight printed (a restarted server has a new key)";
  }
  return {};
}

}  // namespace prizma::relight
