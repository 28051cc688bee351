#pragma once
// The live page's files (relight/web/*), embedded at build time by relight/web/embed.cmake.
#include <string_view>

namespace prizma::relight::detail {

// The content of the embedded file `name` ("index.html", "app.js"); empty when there is none.
std::string_view web_asset(std::string_view name);

}  // namespace prizma::relight::detail
