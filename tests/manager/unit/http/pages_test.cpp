// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include "http/pages.hpp"

using Catch::Contains;
using rfbsim::manager::busy_page;
using rfbsim::manager::completed_page;
using rfbsim::manager::error_page;
using rfbsim::manager::home_page;
using rfbsim::manager::session_ended_page;

namespace {

std::size_t count(const std::string& text, const std::string& part) {
  std::size_t n = 0;
  for (std::size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("every page is a whole HTML document") {
  for (const std::string& page : {home_page(), busy_page(5), completed_page(), session_ended_page("expired"),
                                  error_page(400, "Bad link", "no uid")}) {
    CHECK(page.rfind("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n", 0) == 0);
    CHECK(count(page, "<title>") == 1);
    CHECK(count(page, "<h1>") == 1);
    const std::string end = "</main>\n</body>\n</html>\n";
    REQUIRE(page.size() >= end.size());
    CHECK(page.substr(page.size() - end.size()) == end);
    CHECK(count(page, "<script") == 0);  // nothing to run: the pages work in any sandboxed frame
  }
}

TEST_CASE("the busy page reloads itself after the given seconds") {
  const std::string page = busy_page(7);
  CHECK_THAT(page, Contains("<meta http-equiv=\"refresh\" content=\"7\">"));
  CHECK_THAT(page, Contains("<title>All simulators are busy</title>"));
  CHECK_THAT(page, Contains("busy"));
  CHECK_THAT(page, Contains("in 7 seconds"));
  CHECK_THAT(busy_page(30), Contains("content=\"30\""));
}

TEST_CASE("only the busy page reloads itself") {
  CHECK_THAT(home_page(), !Contains("http-equiv"));
  CHECK_THAT(completed_page(), !Contains("http-equiv"));
  CHECK_THAT(error_page(500, "x", "y"), !Contains("http-equiv"));
}

TEST_CASE("the completed page says so") {
  const std::string page = completed_page();
  CHECK_THAT(page, Contains("<title>Already completed</title>"));
  CHECK_THAT(page, Contains("already been completed"));
}

TEST_CASE("the session-ended page names the state, escaped") {
  CHECK_THAT(session_ended_page("expired"), Contains("has ended (expired)."));
  CHECK_THAT(session_ended_page("<b>"), Contains("has ended (&lt;b&gt;)."));
}

TEST_CASE("an error page escapes its title and message and shows the status") {
  const std::string page = error_page(400, "Bad <link>", "uid '<script>alert(1)</script>' is not valid & \"odd\"");
  CHECK_THAT(page, Contains("<p>uid &#39;&lt;script&gt;alert(1)&lt;/script&gt;&#39; is not valid &amp; &quot;odd&quot;</p>"));
  CHECK_THAT(page, Contains("<title>Bad &lt;link&gt;</title>"));
  CHECK_THAT(page, Contains("<h1>Bad &lt;link&gt;</h1>"));
  CHECK_THAT(page, Contains("Error 400"));
  CHECK_THAT(page, !Contains("<script>"));
  CHECK_THAT(page, !Contains("<link>"));
}

TEST_CASE("the home page says what the server is for") {
  CHECK_THAT(home_page(), Contains("<title>rfbsim</title>"));
  CHECK_THAT(home_page(), Contains("open the link your survey gave you"));
}
