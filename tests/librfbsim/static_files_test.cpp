// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include "static_files.hpp"

using namespace rfbsim::detail;
namespace fs = std::filesystem;

TEST_CASE("paths resolve under the root and '/' is index.html") {
  const fs::path root = "/srv/web";
  CHECK(resolve_static_path(root, "/") == root / "index.html");
  CHECK(resolve_static_path(root, "/novnc/core/rfb.js") == root / "novnc/core/rfb.js");
  CHECK(resolve_static_path(root, "//a/./b.css") == root / "a/b.css");
  CHECK(resolve_static_path(root, "/a%20b.txt") == root / "a b.txt");
}

TEST_CASE("escapes from the root are refused") {
  const fs::path root = "/srv/web";
  CHECK_FALSE(resolve_static_path(root, "/../etc/passwd"));
  CHECK_FALSE(resolve_static_path(root, "/a/%2e%2e/%2e%2e/etc/passwd"));
  CHECK_FALSE(resolve_static_path(root, "/a\\..\\b"));
  CHECK_FALSE(resolve_static_path(root, "/a%00"));
  CHECK_FALSE(resolve_static_path(root, "relative"));
}

TEST_CASE("content types and response heads") {
  CHECK(mime_type_for("a/rfb.js") == "text/javascript; charset=utf-8");
  CHECK(mime_type_for("index.html") == "text/html; charset=utf-8");
  CHECK(mime_type_for("x.unknown") == "application/octet-stream");
  const std::string head = response_head(404, "text/plain", 12);
  CHECK(head.rfind("HTTP/1.1 404 Not Found\r\n", 0) == 0);
  CHECK(head.find("Content-Length: 12\r\n") != std::string::npos);
  CHECK(head.substr(head.size() - 4) == "\r\n\r\n");
}
