// The web dashboard's built files (web/dist), served by the daemon on its own port so the page and
// the API share one origin. Pure of sockets: a request path in, a Response out, so path handling
// (percent-decoding, "..", encoded slashes, symlinks leading out of the directory) is unit-tested.
// Only GET and HEAD; index.html is never cached (it names the hashed assets of the current build),
// files under /assets/ carry a content hash in their name and are cached as immutable, anything
// else is revalidated by its ETag.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "server/http/router.hpp"

namespace synbench::http {

class StaticFiles {
 public:
  static constexpr std::uintmax_t kMaxFileBytes = 64u << 20;  // a dashboard bundle is far smaller

  explicit StaticFiles(std::filesystem::path root) : root_(std::move(root)) {}
  const std::filesystem::path& root() const { return root_; }

  // `target` is the request-target ("/assets/app.js?v=1"); `if_none_match` the If-None-Match
  // header or "". 400 for a path that is malformed or tries to leave the directory, 404 for a
  // missing file, 405 for other methods, 304 when the ETag matches. A path without an extension
  // that names no file is answered with index.html, so the dashboard's client-side routes reload.
  // Without the directory or its index.html, such requests get a page saying the dashboard is
  // not built.
  // `accept_encoding` is the Accept-Encoding header: when it accepts gzip and the file has a
  // "X.gz" beside it, that is sent with Content-Encoding: gzip (Vary: Accept-Encoding on both).
  Response serve(std::string_view method, std::string_view target, std::string_view if_none_match = {},
                 std::string_view accept_encoding = {}) const;

 private:
  std::filesystem::path root_;
};

// Whether an Accept-Encoding header accepts gzip (listed, and not with q=0).
bool accepts_gzip(std::string_view accept_encoding);

// "text/javascript; charset=utf-8" for "app.js", ...; application/octet-stream when unknown.
std::string content_type_for(const std::filesystem::path& file);

}  // namespace synbench::http
