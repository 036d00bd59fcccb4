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

namespace {

// Text as a JavaScript string literal inside a <script>: JSON-escaped, and '<' written as \u003c so that no
// "</script>" can end the element early.
std::string script_string(std::string_view text) {
  std::string out = "\"";
  for (const char ch : json_escape(text)) {
    if (ch == '<') {
      out += "\\u003c";
    } else {
      out.push_back(ch);
    }
  }
  return out + "\"";
}

}  // namespace

std::string recording_unavailable_page(std::string_view uid, const std::vector<std::string>& survey_origins) {
  std::string origins;
  for (const std::string& origin : survey_origins) origins += (origins.empty() ? "" : ",") + script_string(origin);
  // Inline: this page has no files of its own to load, and the manager's pages restrict only their framing.
  const std::string script =
      "<script>\n(function () {\n  if (window.parent === window) return;\n  var origins = [" + origins +
      "];\n  ['unavailable', 'ended'].forEach(function (event) {\n    var message = {type: 'rfbsim', event: event, "
      "uid: " + script_string(uid) + ", code: null, outcome: 'unavailable'};\n    origins.forEach(function (origin) "
      "{\n      try { window.parent.postMessage(message, origin); } catch (err) { /* a malformed origin */ }\n    "
      "});\n  });\n})();\n</script>";
  return layout("No recording to watch right now",
                "<p>This part of the study shows a recording of an earlier session, and none is free for you at the "
                "moment. Please go back to the survey, or tell the researcher.</p>\n<p><small>Error 503</small></p>\n" +
                    script);
}

std::string error_page(int status, std::string_view title, std::string_view message) {
  return layout(title, "<p>" + html_escape(message) + "</p>\n<p><small>Error " + std::to_string(status) +
                           "</small></p>");
}

}  // namespace rfbsim::manager
