// SPDX-License-Identifier: GPL-2.0-or-later
// The manager's own pages: one layout, a few sentences each.
#include "http/pages.hpp"

#include "http/web_policy.hpp"

namespace rfbsim::manager {

namespace {

std::string layout(std::string_view title, std::string_view body, std::string_view head_extra = "") {
  std::string page =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>";
  page += html_escape(title);
  page += "</title>\n";
  page += head_extra;
  page +=
      "<style>body{font-family:system-ui,sans-serif;background:#1e1e1e;color:#eee;margin:0;display:flex;"
      "min-height:100vh;align-items:center;justify-content:center}main{max-width:36em;padding:2em}"
      "h1{font-size:1.4em}</style>\n</head>\n<body>\n<main>\n<h1>";
  page += html_escape(title);
  page += "</h1>\n";
  page += body;
  page += "\n</main>\n</body>\n</html>\n";
  return page;
}

}  // namespace

std::string home_page() {
  return layout("rfbsim", "<p>This server runs simulations for online studies. Please open the link your survey "
                          "gave you.</p>");
}

std::string busy_page(int retry_seconds) {
  const std::string seconds = std::to_string(retry_seconds);
  return layout("All simulators are busy",
                "<p>Every simulator is in use right now. This page tries again by itself in " + seconds +
                    " seconds; please keep it open.</p>",
                "<meta http-equiv=\"refresh\" content=\"" + seconds + "\">\n");
}

std::string retry_later_page(int retry_seconds) {
  const std::string seconds = std::to_string(retry_seconds);
  return layout("Please try again in a moment",
                "<p>The study's servers could not agree on a simulator for you just now. This page tries again by "
                "itself in " + seconds + " seconds; please keep it open.</p>",
                "<meta http-equiv=\"refresh\" content=\"" + seconds + "\">\n");
}

std::string previous_closing_page(int retry_seconds) {
  const std::string seconds = std::to_string(retry_seconds);
  return layout("Your previous session is closing",
                "<p>Your earlier session with this link is still closing. This page tries again by itself in " +
                    seconds + " seconds; please keep it open.</p>",
                "<meta http-equiv=\"refresh\" content=\"" + seconds + "\">\n");
}

std::string completed_page() {
  return layout("Already completed",
                "<p>This link's session has already been completed, and each link can be used once. "
                "Please go back to the survey.</p>");
}

std::string session_ended_page(std::string_view state) {
  return layout("This session has ended",
                "<p>The simulation behind this link has ended (" + html_escape(state) +
                    "). Please go back to the survey.</p>");
}

std::string error_page(int status, std::string_view title, std::string_view message) {
  return layout(title, "<p>" + html_escape(message) + "</p>\n<p><small>Error " + std::to_string(status) +
                           "</small></p>");
}

}  // namespace rfbsim::manager
