// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>
#include <fstream>

#include "http/page_files.hpp"
#include "scratch_dir.hpp"

using rfbsim::manager::admin_page_file;
using rfbsim::manager::read_page_file;

TEST_CASE("page files: /admin reaches only the admin page and its script") {
  CHECK(admin_page_file("") == "admin.html");
  CHECK(admin_page_file("admin.js") == "admin.js");
  CHECK_FALSE(admin_page_file("index.html"));
  CHECK_FALSE(admin_page_file("../admin.js"));
}

TEST_CASE("page files: a file is read whole, and a folder or a missing file is nothing") {
  rfbsim::test::ScratchDir dir("rfbsim-page-files");
  const auto page = dir.path() / "page.html";
  std::ofstream(page, std::ios::binary) << std::string("<p>\0binary</p>", 14);
  CHECK(read_page_file(page) == std::string("<p>\0binary</p>", 14));
  CHECK_FALSE(read_page_file(dir.path()));
  CHECK_FALSE(read_page_file(dir.path() / "missing.html"));
}
