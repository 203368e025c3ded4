// Path checks, content types and caching of the dashboard's files; see static_files.hpp.
#include "server/http/static_files.hpp"

#include <fstream>
#include <optional>
#include <sstream>
#include <variant>
#include <vector>

#include "drivers/utf8.hpp"
#include "server/http/url_text.hpp"

namespace synbench::http {

namespace fs = std::filesystem;

namespace {

constexpr const char* kImmutable = "public, max-age=31536000, immutable";

const char* const kNotBuiltPage = R"(<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>synbench: dashboard not built</title></head>
<body style="font-family: sans-serif; max-width: 40em; margin: 3em auto">
<h1>synbench</h1>
<p>The daemon runs, but the web dashboard is not built: its directory has no index.html.</p>
<p>Build it with <code>scripts/build.sh</code> (the dashboard lands in <code>web/dist/</code>), or start
the daemon with <code>--web-dir DIR</code> (or <code>SYNBENCH_WEB_DIR</code>) naming a built dashboard.</p>
<p>The REST API answers meanwhile: <a href="/api/health">/api/health</a>,
<a href="/api/openapi.json">/api/openapi.json</a>.</p>
</body></html>
)";

Response plain_error(int status, const std::string& code, const std::string& message) {
  Response r = error_response(status, code, message);
  r.headers.emplace_back("Cache-Control", "no-store");
  return r;
}

Response not_built() {
  Response r;
  r.status = 404;
  r.content_type = "text/html; charset=utf-8";
  r.body = kNotBuiltPage;
  r.headers.emplace_back("Cache-Control", "no-store");
  return r;
}

// The decoded segments of `path`, or a reason it is refused. Encoded slashes and backslashes are
// refused before decoding: after it they would be indistinguishable from separators.
std::variant<std::vector<std::string>, std::string> split_path(std::string_view path) {
  if (path.empty() || path.front() != '/') return std::string("the path must start with /");
  const std::string low = ascii_lower(path);
  if (low.find("%2f") != std::string::npos || low.find("%5c") != std::string::npos || path.find('\\') != std::string_view::npos)
    return std::string("encoded slashes and backslashes are not allowed in a path");
  std::vector<std::string> segs;
  std::string cur;
  auto flush = [&]() -> std::optional<std::string> {
    if (cur == "." || cur == "..") return std::string("'.' and '..' segments are not allowed");
    if (!cur.empty()) segs.push_back(cur);
    cur.clear();
    return std::nullopt;
  };
  for (std::size_t i = 0; i < path.size(); ++i) {
    char c = path[i];
    if (c == '/') {
      if (auto e = flush()) return *e;
      continue;
    }
    if (c == '%') {
      const auto decoded = percent_decode(path.substr(i, 3), Plus::literal);
      if (!decoded) return std::string("malformed percent-encoding");
      c = decoded->front();
      i += 2;
      if (c == '\0') return std::string("NUL in a path");
    }
    cur.push_back(c);
  }
  if (auto e = flush()) return *e;
  return segs;
}

// True when `p` is `root` or below it, both canonical.
bool inside(const fs::path& root, const fs::path& p) {
  auto r = root.begin(), q = p.begin();
  for (; r != root.end(); ++r, ++q)
    if (q == p.end() || *r != *q) return false;
  return true;
}

std::string etag_of(const fs::path& file, std::uintmax_t size, std::error_code& ec) {
  const auto mtime = fs::last_write_time(file, ec);
  std::ostringstream s;
  s << "W/\"" << std::hex << size << "-" << mtime.time_since_epoch().count() << "\"";
  return s.str();
}

bool etag_matches(std::string_view if_none_match, const std::string& etag) {
  if (if_none_match.empty()) return false;
  if (if_none_match.find('*') != std::string_view::npos) return true;
  // Weak comparison: W/"x" matches "x" and W/"x".
  const std::string_view opaque = std::string_view(etag).substr(2);
  return if_none_match.find(opaque) != std::string_view::npos;
}

}  // namespace

bool accepts_gzip(std::string_view accept_encoding) {
  // "gzip", "gzip;q=0.5", "deflate, gzip": yes; "gzip;q=0", "identity": no. "*" is not taken as
  // gzip: a client that names no coding gets the plain file.
  const std::string a = ascii_lower(accept_encoding);
  std::size_t pos = 0;
  while (pos <= a.size()) {
    std::size_t end = a.find(',', pos);
    if (end == std::string::npos) end = a.size();
    std::string item = a.substr(pos, end - pos);
    std::erase(item, ' ');
    std::erase(item, '\t');
    const std::size_t semi = item.find(';');
    if (item.substr(0, semi) == "gzip") {
      if (semi == std::string::npos) return true;
      const std::string params = item.substr(semi + 1);
      return !(params.rfind("q=0", 0) == 0 && params.find_first_not_of("q=0.") == std::string::npos);
    }
    pos = end + 1;
  }
  return false;
}

std::string content_type_for(const fs::path& file) {
  static const std::pair<const char*, const char*> types[] = {
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".map", "application/json"},
      {".webmanifest", "application/manifest+json"},
      {".svg", "image/svg+xml"},
      {".png", "image/png"},
      {".jpg", "image/jpeg"},
      {".jpeg", "image/jpeg"},
      {".gif", "image/gif"},
      {".webp", "image/webp"},
      {".ico", "image/x-icon"},
      {".woff", "font/woff"},
      {".woff2", "font/woff2"},
      {".ttf", "font/ttf"},
      {".txt", "text/plain; charset=utf-8"},
      {".csv", "text/csv; charset=utf-8"},
      {".wasm", "application/wasm"},
  };
  const std::string ext = ascii_lower(file.extension().string());
  for (const auto& [e, t] : types)
    if (ext == e) return t;
  return "application/octet-stream";
}

Response StaticFiles::serve(std::string_view method, std::string_view target, std::string_view if_none_match,
                           std::string_view accept_encoding) const {
  if (method != "GET" && method != "HEAD") {
    Response r = plain_error(405, "method_not_allowed", std::string(method) + " is not allowed on static files (allowed: GET, HEAD)");
    r.headers.emplace_back("Allow", "GET, HEAD");
    return r;
  }
  const std::string_view path = target.substr(0, target.find_first_of("?#"));
  auto split = split_path(path);
  if (auto* why = std::get_if<std::string>(&split)) return plain_error(400, "bad_path", *why);
  const auto& segs = std::get<std::vector<std::string>>(split);

  std::error_code ec;
  const fs::path root = fs::canonical(root_, ec);
  const bool has_index = !ec && fs::is_regular_file(root / "index.html", ec);
  fs::path rel;
  for (const auto& s : segs) rel /= s;
  // A client-side route of the dashboard ("/sweeps/3") has no extension and names no file.
  const bool route_like = segs.empty() || segs.back().find('.') == std::string::npos;

  fs::path file;
  if (!segs.empty() && has_index) {
    const fs::path resolved = fs::canonical(root / rel, ec);
    if (!ec) {
      // A symlink may point anywhere: only what resolves inside the directory is served.
      if (!inside(root, resolved)) return plain_error(404, "not_found", "no file " + drivers::escape_invalid_utf8(path));
      file = fs::is_directory(resolved, ec) ? resolved / "index.html" : resolved;
    }
  }
  if (file.empty() || !fs::is_regular_file(file, ec)) {
    if (!route_like) return plain_error(404, "not_found", "no file " + drivers::escape_invalid_utf8(path));
    if (!has_index) return not_built();
    file = root / "index.html";
  }

  // The build writes a gzip of each file beside it (web/vite.config.js): sent as is to a client
  // that accepts gzip, so the dashboard's 700 KB go over the wire as ~250 KB, with no
  // compression work on the io thread.
  fs::path gz = file;
  gz += ".gz";
  // As for the file itself: only a .gz whose real path lies inside the directory.
  const bool has_gz = fs::is_regular_file(gz, ec) && inside(root, fs::canonical(gz, ec));
  const bool send_gz = has_gz && accepts_gzip(accept_encoding);
  const fs::path sent = send_gz ? gz : file;
  const auto size = fs::file_size(sent, ec);
  if (ec) return plain_error(404, "not_found", "no file " + drivers::escape_invalid_utf8(path));
  if (size > kMaxFileBytes) return plain_error(500, "file_too_large", drivers::escape_invalid_utf8(path) + " is larger than the daemon serves");

  Response r;
  r.content_type = content_type_for(file);
  const bool html = ascii_lower(file.extension().string()) == ".html";
  const std::string rel_file = fs::relative(file, root, ec).generic_string();
  if (has_gz) r.headers.emplace_back("Vary", "Accept-Encoding");
  if (send_gz) r.headers.emplace_back("Content-Encoding", "gzip");
  if (html) {
    r.headers.emplace_back("Cache-Control", "no-store");
  } else {
    r.headers.emplace_back("Cache-Control", rel_file.rfind("assets/", 0) == 0 ? kImmutable : "no-cache");
    const std::string etag = etag_of(sent, size, ec);  // the two encodings are two representations
    r.headers.emplace_back("ETag", etag);
    if (etag_matches(if_none_match, etag)) {
      r.status = 304;
      return r;
    }
  }
  std::ifstream in(sent, std::ios::binary);
  std::string body(static_cast<std::size_t>(size), '\0');
  if (!in.read(body.data(), static_cast<std::streamsize>(size))) return plain_error(500, "read_failed", "cannot read " + drivers::escape_invalid_utf8(path));
  r.body = std::move(body);
  return r;
}

}  // namespace synbench::http
