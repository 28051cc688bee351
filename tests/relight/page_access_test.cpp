// Who may use the live page (page_access.h): Host, the page's own origin, and the run's secret.
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "prizma/relight/page_access.h"

namespace prizma::relight {
namespace {

const std::string kToken = "0123456789abcdef0123456789abcdef";

RequestOrigin from_page() { return {"127.0.0.1:8123", "", "same-origin", kToken}; }

TEST(PageAccess, LetsThePageItselfUseTheApi) {
  const PageAccess access(kToken, "127.0.0.1", 8123);
  EXPECT_EQ(access.refusal("/api/info", from_page()), "");
  RequestOrigin post = from_page();
  post.origin = "http://127.0.0.1:8123";  // browsers send Origin with a POST from the page too
  EXPECT_EQ(access.refusal("/api/save", post), "");
  RequestOrigin other_name = from_page();
  other_name.host = "localhost:8123";
  other_name.origin = "http://localhost:8123";
  EXPECT_EQ(access.refusal("/api/weights", other_name), "");
  RequestOrigin typed = from_page();
  typed.fetch_site = "none";  // typed into the address bar (still needs the secret)
  EXPECT_EQ(access.refusal("/api/info", typed), "");
  RequestOrigin script = from_page();
  script.fetch_site.clear();  // a script or an old browser: no Fetch Metadata
  EXPECT_EQ(access.refusal("/api/info", script), "");
}

TEST(PageAccess, RefusesTheApiWithoutTheSecretOrWithAnotherOne) {
  const PageAccess access(kToken, "127.0.0.1", 8123);
  RequestOrigin r = from_page();
  r.token.clear();
  EXPECT_NE(access.refusal("/api/transport", r).find("no access key (X-Prizma-Token)"), std::string::npos);
  for (const std::string& wrong :
       std::vector<std::string>{"0123456789abcdef0123456789abcdeF", "0123456789abcdef", kToken + "0", "x"}) {
    r.token = wrong;
    EXPECT_NE(access.refusal("/api/info", r).find("wrong access key"), std::string::npos) << wrong;
  }
}

TEST(PageAccess, RefusesRequestsFromOtherPagesEvenWithTheSecret) {
  const PageAccess access(kToken, "127.0.0.1", 8123);
  for (const char* site : {"cross-site", "same-site"}) {
    RequestOrigin r = from_page();
    r.fetch_site = site;
    EXPECT_EQ(access.refusal("/api/save", r),
              std::string("a request from another page (Sec-Fetch-Site: ") + site + ") may not use this server");
  }
  for (const char* origin : {"http://localhost:8000", "null", "http://127.0.0.1:8124", "https://127.0.0.1:8123"}) {
    RequestOrigin r = from_page();
    r.fetch_site.clear();
    r.origin = origin;
    EXPECT_EQ(access.refusal("/api/info", r), std::string("a request from another page (Origin ") + origin +
                                                  ", this page is http://127.0.0.1:8123) may not use this server");
  }
}

TEST(PageAccess, ThePageItselfIsPublicButNotThroughAForeignHost) {
  const PageAccess access(kToken, "127.0.0.1", 8123);
  EXPECT_EQ(access.refusal("/", {"127.0.0.1:8123", "http://evil.example", "cross-site", ""}), "");
  EXPECT_EQ(access.refusal("/app.js", {"[::1]:8123", "", "", ""}), "");
  // DNS rebinding: evil.example resolving to 127.0.0.1 names itself in Host.
  EXPECT_EQ(access.refusal("/", {"evil.example:8123", "", "", ""}),
            "Host \"evil.example:8123\" is not this server's loopback address");
  EXPECT_NE(access.refusal("/api/info", {"127.0.0.1:9999", "", "", kToken}), "");
}

TEST(PageAccess, OffLoopbackAnyHostButTheOriginMustBeItsOwn) {
  const PageAccess access(kToken, "0.0.0.0", 8123);
  EXPECT_EQ(access.refusal("/api/info", {"render-box:8123", "http://render-box:8123", "same-origin", kToken}), "");
  EXPECT_NE(access.refusal("/api/info", {"render-box:8123", "http://elsewhere", "", kToken}), "");
}

TEST(PageAccess, NewTokensAre128RandomBitsInHex) {
  std::set<std::string> seen;
  for (int i = 0; i < 100; ++i) {
    const std::string t = PageAccess::new_token();
    ASSERT_EQ(t.size(), 32u);
    EXPECT_EQ(t.find_first_not_of("0123456789abcdef"), std::string::npos) << t;
    seen.insert(t);
  }
  EXPECT_EQ(seen.size(), 100u);
}

TEST(PageAccess, SameSecretComparesWholeStrings) {
  EXPECT_TRUE(same_secret(kToken, kToken));
  EXPECT_FALSE(same_secret(kToken, kToken.substr(0, 31) + "0"));
  EXPECT_FALSE(same_secret(kToken, kToken.substr(0, 31)));
  EXPECT_FALSE(same_secret("", "a"));
  EXPECT_TRUE(same_secret("", ""));
}

}  // namespace
}  // namespace prizma::relight
