// The dashboard's static files without a socket: path checks (dot segments, encoded slashes,
// symlinks out of the directory), content types, caching headers, ETag, the "not built" page;
// the WebSocket's allowed origins and the hub's push messages.
#include "server/http/static_files.hpp"

#include <unistd.h>

#include <fstream>

#include <gtest/gtest.h>

#include "server/http/http_server.hpp"
#include "server/http/ws_hub.hpp"

namespace synbench::http {
namespace {

namespace fs = std::filesystem;

std::string header(const Response& r, const std::string& name) {
  for (const auto& [k, v] : r.headers)
    if (k == name) return v;
  return "";
}

struct Static : ::testing::Test {
  Static() {
    base = fs::temp_directory_path() / ("synbench-static-" + std::to_string(::getpid()));
    fs::remove_all(base);
    fs::create_directories(base / "web" / "assets");
    write(base / "web" / "index.html", "<html>dash</html>");
    write(base / "web" / "assets" / "app-1f2e.js", "console.log(1)");
    write(base / "web" / "logo.svg", "<svg/>");
    write(base / "secret.txt", "SECRET");
    fs::create_symlink(base / "secret.txt", base / "web" / "out.txt");
  }
  ~Static() override { fs::remove_all(base); }
  static void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }
  fs::path base;
};

TEST_F(Static, ServesIndexAndAssetsWithTypesAndCaching) {
  StaticFiles files(base / "web");
  auto r = files.serve("GET", "/");
  EXPECT_EQ(r.status, 200);
  EXPECT_EQ(r.body, "<html>dash</html>");
  EXPECT_EQ(r.content_type, "text/html; charset=utf-8");
  EXPECT_EQ(header(r, "Cache-Control"), "no-store");
  r = files.serve("GET", "/assets/app-1f2e.js?v=2");
  EXPECT_EQ(r.status, 200);
  EXPECT_EQ(r.content_type, "text/javascript; charset=utf-8");
  EXPECT_NE(header(r, "Cache-Control").find("immutable"), std::string::npos);
  const std::string etag = header(r, "ETag");
  ASSERT_FALSE(etag.empty());
  EXPECT_EQ(files.serve("GET", "/assets/app-1f2e.js", etag).status, 304);
  EXPECT_EQ(files.serve("HEAD", "/logo.svg").status, 200);
  EXPECT_EQ(header(files.serve("GET", "/logo.svg"), "Cache-Control"), "no-cache");
  EXPECT_EQ(files.serve("GET", "/runs/7").body, "<html>dash</html>");  // a client-side route
  EXPECT_EQ(files.serve("GET", "/missing.js").status, 404);
  r = files.serve("POST", "/");
  EXPECT_EQ(r.status, 405);
  EXPECT_EQ(header(r, "Allow"), "GET, HEAD");
}

TEST_F(Static, NeverLeavesTheDirectory) {
  StaticFiles files(base / "web");
  for (const char* target : {"/../secret.txt", "/assets/../../secret.txt", "/%2e%2e/secret.txt", "/%2E%2e/secret.txt",
                             "/..%2fsecret.txt", "/assets%2F..%2F..%2Fsecret.txt", "/..%5csecret.txt", "/a\\..\\secret.txt",
                             "/%00", "/%zz", "/.", "relative.txt", "/out.txt"}) {
    const auto r = files.serve("GET", target);
    EXPECT_TRUE(r.status == 400 || r.status == 404) << target << " -> " << r.status;
    EXPECT_EQ(r.body.find("SECRET"), std::string::npos) << target;
  }
}

TEST_F(Static, MissingDirectoryGivesTheNotBuiltPage) {
  StaticFiles files(base / "nowhere");
  auto r = files.serve("GET", "/");
  EXPECT_EQ(r.status, 404);
  EXPECT_NE(r.body.find("not built"), std::string::npos);
  EXPECT_NE(r.body.find("scripts/build.sh"), std::string::npos);
  EXPECT_EQ(files.serve("GET", "/assets/app.js").status, 404);
  fs::remove(base / "web" / "index.html");
  EXPECT_NE(StaticFiles(base / "web").serve("GET", "/").body.find("not built"), std::string::npos);
}

// The build's "X.gz" beside a file: sent with Content-Encoding gzip to a client that accepts gzip,
// the plain file otherwise; Vary: Accept-Encoding on both answers; a file without one is plain.
TEST_F(Static, ServesTheGzipOfAFileToAClientThatAcceptsIt) {
  write(base / "web" / "assets" / "app-1f2e.js.gz", "GZ-BYTES");
  StaticFiles files(base / "web");
  auto r = files.serve("GET", "/assets/app-1f2e.js", "", "gzip, deflate, br");
  EXPECT_EQ(r.status, 200);
  EXPECT_EQ(r.body, "GZ-BYTES");
  EXPECT_EQ(header(r, "Content-Encoding"), "gzip");
  EXPECT_EQ(header(r, "Vary"), "Accept-Encoding");
  EXPECT_EQ(r.content_type, "text/javascript; charset=utf-8") << "the type of what it decodes to";
  const std::string gz_etag = header(r, "ETag");
  for (const char* ae : {"", "identity", "br", "gzip;q=0", "deflate, gzip; q=0.0"}) {
    r = files.serve("GET", "/assets/app-1f2e.js", "", ae);
    EXPECT_EQ(r.body, "console.log(1)") << ae;
    EXPECT_EQ(header(r, "Content-Encoding"), "") << ae;
    EXPECT_EQ(header(r, "Vary"), "Accept-Encoding") << ae;
    EXPECT_NE(header(r, "ETag"), gz_etag) << "two representations, two ETags";
  }
  EXPECT_EQ(files.serve("GET", "/assets/app-1f2e.js", "", "GZIP;q=0.8").body, "GZ-BYTES");
  r = files.serve("GET", "/logo.svg", "", "gzip");
  EXPECT_EQ(r.body, "<svg/>");
  EXPECT_EQ(header(r, "Content-Encoding"), "");
  EXPECT_EQ(header(r, "Vary"), "");
}

TEST(ContentType, ByExtension) {
  EXPECT_EQ(content_type_for("a.CSS"), "text/css; charset=utf-8");
  EXPECT_EQ(content_type_for("a.woff2"), "font/woff2");
  EXPECT_EQ(content_type_for("a.json"), "application/json");
  EXPECT_EQ(content_type_for("a"), "application/octet-stream");
}

// A Host header naming 0.0.0.0 is no name of the daemon's: only --allow-host names pass.
TEST(Origins, AnUnspecifiedListenAddressAllowsNoHostOfItsOwn) {
  EXPECT_TRUE(allowed_hosts("0.0.0.0", 8080).empty());
  EXPECT_TRUE(allowed_hosts("::", 8080).empty());
  EXPECT_TRUE(allowed_hosts("192.0.2.7", 8080).count("192.0.2.7:8080"));
}

TEST(Origins, HttpOfEachAllowedHostAndTheExtraOnes) {
  const auto o = allowed_origins(allowed_hosts("127.0.0.1", 8080), {"http://Dash.example:5173"});
  EXPECT_TRUE(o.count("http://127.0.0.1:8080"));
  EXPECT_TRUE(o.count("http://localhost:8080"));
  EXPECT_TRUE(o.count("http://[::1]:8080"));
  EXPECT_TRUE(o.count("http://dash.example:5173"));
  EXPECT_FALSE(o.count("https://127.0.0.1:8080"));
  EXPECT_FALSE(o.count("http://127.0.0.1"));
}

TEST(HubMessages, NullsWhileTheLinkIsDown) {
  BenchStatus s;
  const auto t = synbench::Json::parse(telemetry_message(s, 12.5));
  EXPECT_EQ(t["type"], "telemetry");
  EXPECT_EQ(t["sent_unix_ms"], 12.5);
  EXPECT_TRUE(t["speed_rpm"].is_null());
  EXPECT_TRUE(t["pos_err_deg"].is_null());
  EXPECT_EQ(t["phase"], "normal");
  const auto sw = sweep_json(s, std::nullopt);
  EXPECT_TRUE(sw["id"].is_null());
  s.sweep = app::SweepInfo{4, "running", 2, 10, "", std::nullopt, std::nullopt};
  EXPECT_EQ(sweep_json(s, 8.0)["eta_s"], 8.0);
  const auto e = synbench::Json::parse(event_message(BenchEvent{1.5, "fault", "overcurrent", 7}));
  EXPECT_EQ(e["seq"], 7);
  EXPECT_EQ(e["kind"], "fault");
  EXPECT_EQ(synbench::Json::parse(state_message(s))["type"], "state");
}

}  // namespace
}  // namespace synbench::http
