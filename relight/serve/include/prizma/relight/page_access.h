#pragma once
// Who may use the live page (prizma-relight --serve; docs/relight.md, "Who can use the page").
// The page and its script are public (they hold no data); every /api request must
//  - name this server in Host when it is bound to loopback (no DNS rebinding from other sites),
//  - come from the page itself: a Sec-Fetch-Site other than same-origin / none, or an Origin other
//    than this server's own, is refused (what browsers send for requests from other pages), and
//  - carry the run's secret in the X-Prizma-Token header. The secret is printed in the page's URL
//    fragment, which browsers never send to a server nor in a Referer; a custom header makes a
//    browser ask the server first (a CORS preflight) for any other origin, which is never granted,
//    so a page elsewhere cannot send it even "no-cors".
#include <string>
#include <string_view>

namespace prizma::relight {

// The headers of a request that the access rules read ("" where absent).
struct RequestOrigin {
  std::string host;        // Host
  std::string origin;      // Origin
  std::string fetch_site;  // Sec-Fetch-Site
  std::string token;       // X-Prizma-Token
};

class PageAccess {
 public:
  static constexpr const char* kTokenHeader = "X-Prizma-Token";

  // A fresh 128-bit secret from the kernel's generator (getrandom(2)) as 32 hex digits.
  // Throws RuntimeError when the generator fails.
  static std::string new_token();

  // `bind`: the address listened on; only loopback binds check Host (any Host may reach another).
  PageAccess(std::string token, std::string bind, int port);

  const std::string& token() const { return m_token; }

  // Why a request for `path` is refused (the 403 message), or "" when it may proceed. Every path
  // checks Host; /api/ paths also the origin and the secret.
  std::string refusal(std::string_view path, const RequestOrigin& request) const;

 private:
  std::string m_token;
  std::string m_bind;
  int m_port;
};

// True for 127.0.0.0/8, ::1 and "localhost".
bool is_loopback_address(const std::string& address);

// Equal strings, compared in a time that does not depend on where they first differ.
bool same_secret(std::string_view a, std::string_view b);

}  // namespace prizma::relight
