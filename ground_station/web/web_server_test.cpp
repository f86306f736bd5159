#include "ground_station/web/web_server.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "common/config_error.hpp"

using namespace ddswarm;
using namespace ddswarm::gs::web;
namespace fs = std::filesystem;

namespace {

class StaticFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    base_ = fs::temp_directory_path() / ("ddswarm-web-test-" + std::to_string(getpid()));
    root_ = base_ / "www";
    fs::create_directories(root_ / "js");
    fs::create_directories(root_ / "node_modules/three/build");
    write(root_ / "index.html", "<html>");
    write(root_ / "js/app.js", "x");
    write(root_ / "node_modules/three/build/three.module.js", "three");
    write(root_ / ".secret", "s");
    write(base_ / "outside.txt", "o");
    fs::create_symlink(base_ / "outside.txt", root_ / "link.txt");
  }
  void TearDown() override { fs::remove_all(base_); }
  static void write(const fs::path& p, const char* text) { std::ofstream(p) << text; }
  std::optional<fs::path> get(const char* target) { return resolve_static_path(root_, target); }
  fs::path canon(const fs::path& p) { return fs::canonical(p); }

  fs::path base_, root_;
};

}  // namespace

TEST_F(StaticFiles, ServesFilesUnderTheRootAndThreeUnderVendor) {
  EXPECT_EQ(get("/"), canon(root_ / "index.html"));
  EXPECT_EQ(get("/index.html?x=1"), canon(root_ / "index.html"));
  EXPECT_EQ(get("/js/app.js"), canon(root_ / "js/app.js"));
  EXPECT_EQ(get("/js/%61pp.js"), canon(root_ / "js/app.js"));
  EXPECT_EQ(get("/vendor/three/build/three.module.js"),
            canon(root_ / "node_modules/three/build/three.module.js"));
}

TEST_F(StaticFiles, RefusesTraversalHiddenFilesAndEscapes) {
  for (const char* t : {"/../outside.txt", "/js/../../outside.txt", "/%2e%2e/outside.txt",
                        "/js/%2E%2E/%2E%2E/outside.txt", "/vendor/three/../../../outside.txt",
                        "/.secret", "/js\\..\\..\\outside.txt", "/link.txt", "/missing.js",
                        "relative", "", "/%zz", "/%2", "/js/app.js%00.png", "/js"})
    EXPECT_FALSE(get(t).has_value()) << t;
}

TEST(WebServer, MimeTypes) {
  EXPECT_EQ(mime_type("a/index.html"), "text/html; charset=utf-8");
  EXPECT_EQ(mime_type("three.module.js"), "text/javascript; charset=utf-8");
  EXPECT_EQ(mime_type("x.MJS"), "text/javascript; charset=utf-8");
  EXPECT_EQ(mime_type("style.css"), "text/css; charset=utf-8");
  EXPECT_EQ(mime_type("shot.png"), "image/png");
  EXPECT_EQ(mime_type("package.json"), "application/json");
  EXPECT_EQ(mime_type("blob.bin"), "application/octet-stream");
}

TEST(WebServer, SameOrigin) {
  EXPECT_TRUE(same_origin("", "127.0.0.1:8080"));
  EXPECT_TRUE(same_origin("http://127.0.0.1:8080", "127.0.0.1:8080"));
  EXPECT_TRUE(same_origin("http://LOCALHOST:8080/", "localhost:8080"));
  EXPECT_FALSE(same_origin("http://evil.example", "127.0.0.1:8080"));
  EXPECT_FALSE(same_origin("http://127.0.0.1:9999", "127.0.0.1:8080"));
  EXPECT_FALSE(same_origin("null", "127.0.0.1:8080"));
}

TEST(WebServer, ListenAddress) {
  WebServerConfig c;
  parse_listen_address("127.0.0.1:0", c);
  EXPECT_EQ(c.address, "127.0.0.1");
  EXPECT_EQ(c.port, 0);
  parse_listen_address("[::1]:8080", c);
  EXPECT_EQ(c.address, "::1");
  EXPECT_EQ(c.port, 8080);
  for (const char* bad : {"8080", "127.0.0.1", "127.0.0.1:", "127.0.0.1:65536", "127.0.0.1:-1",
                          "localhost:80", "127.0.0.1:80x", "::1:80", "1.2.3:80"}) {
    try {
      parse_listen_address(bad, c);
      ADD_FAILURE() << bad << " accepted";
    } catch (const FieldError& e) {
      EXPECT_NE(std::string(e.what()).find("--web = "), std::string::npos) << e.what();
    }
  }
}

TEST(WebServer, RefusesRemoteAddressesUnlessAllowed) {
  WebServerConfig c;
  c.web_root = fs::temp_directory_path();
  c.address = "0.0.0.0";
  EXPECT_THROW(c.validate(), FieldError);
  c.allow_remote = true;
  EXPECT_NO_THROW(c.validate());
  c.address = "127.0.0.2";
  c.allow_remote = false;
  EXPECT_NO_THROW(c.validate());
  c.web_root = "/nonexistent/www";
  EXPECT_THROW(c.validate(), FieldError);
}
