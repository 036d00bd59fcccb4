// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>

#include "config/config.hpp"
#include "config/settings_docs.hpp"
#include "config/settings_table.hpp"
#include "file_text.hpp"

using Catch::Contains;
using rfbsim::manager::kSettingsDocsBegin;
using rfbsim::manager::kSettingsDocsEnd;
using rfbsim::manager::settings_markdown;

namespace {

const std::string kDeploymentDoc = std::string(RFBSIM_SOURCE_DIR) + "/docs/deployment.md";

}  // namespace

// The docs' table is the generated one, character for character. After a change to the table, set
// RFBSIM_WRITE_SETTINGS_DOCS=1 and run this test once to write it into docs/deployment.md.
TEST_CASE("the docs' settings table is the declared one") {
  std::string doc = rfbsim::test::file_text(kDeploymentDoc);
  const std::size_t begin = doc.find(kSettingsDocsBegin);
  const std::size_t end = doc.find(kSettingsDocsEnd);
  REQUIRE(begin != std::string::npos);
  REQUIRE(end != std::string::npos);
  REQUIRE(begin < end);
  const std::size_t table_start = begin + std::string(kSettingsDocsBegin).size() + 1;
  const std::string in_doc = doc.substr(table_start, end - table_start);
  const std::string generated = settings_markdown();
  if (in_doc != generated && std::getenv("RFBSIM_WRITE_SETTINGS_DOCS") != nullptr) {
    doc.replace(table_start, end - table_start, generated);
    std::ofstream(kDeploymentDoc) << doc;
    WARN("wrote the settings table into " << kDeploymentDoc);
    return;
  }
  // The first line that differs, rather than the whole table.
  std::istringstream doc_lines(in_doc);
  std::istringstream generated_lines(generated);
  std::string doc_line;
  std::string generated_line;
  while (std::getline(generated_lines, generated_line)) {
    if (!std::getline(doc_lines, doc_line) || doc_line != generated_line) break;
  }
  INFO("docs/deployment.md has: " << doc_line);
  INFO("the table declares:     " << generated_line);
  INFO("(RFBSIM_WRITE_SETTINGS_DOCS=1 and this test write the declared table into the docs)");
  CHECK(in_doc == generated);
}

TEST_CASE("the docs' table and --help name every setting, with its default and range") {
  const std::string table = settings_markdown();
  const std::string help = rfbsim::manager::manager_usage();
  for (const auto& setting : rfbsim::manager::config_table::settings()) {
    CHECK_THAT(table, Contains("| `" + rfbsim::manager::config_table::file_name_of(setting.key) + "` |"));
    const std::string flag = setting.key == "session_args"            ? "--session-arg"
                             : setting.key == "after_session_command" ? "--after-session-command"
                                                                      : rfbsim::manager::config_table::flag_of(setting.key);
    CHECK_THAT(help, Contains("  " + flag + " "));
  }
  CHECK_THAT(table, Contains("| `max_sessions` | `4` | live sessions at once; the next participant is told to wait "
                             "(1..10000) |"));
  CHECK_THAT(help, Contains("--max-sessions N        live sessions at once; the next participant is told to wait "
                            "(1..10000; default 4)"));
  CHECK_THAT(table, Contains("| `ros.namespace` | `/rfbsim` |"));
  CHECK_THAT(help, Contains("--ros-namespace NS"));
}
