// SPDX-License-Identifier: GPL-2.0-or-later
// The report's pure pieces: number formatting and escaping, the command line, the progress bar, plot
// simplification, Hall-zone bins, and docs/report.md defining every column the CSV files have.
#include <catch2/catch.hpp>

#include <Eigen/Core>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "group_summary.hpp"
#include "progress_bar.hpp"
#include "report_cli.hpp"
#include "report_columns.hpp"
#include "report_csv.hpp"
#include "text_format.hpp"
#include "trajectory_plot.hpp"
#include "zone_histogram.hpp"

using namespace rfbsim::report;

TEST_CASE("numbers are written with fixed decimals, compactly in CSV, and never as minus zero") {
  CHECK(format_number(5.0) == "5");
  CHECK(format_number(0.25) == "0.25");
  CHECK(format_number(1.0 / 3.0) == "0.333333");
  CHECK(format_number(-1e-9) == "0");
  CHECK(format_fixed(-0.0001, 3) == "0.000");
  CHECK(format_fixed(2.5, 1) == "2.5");
  CHECK(format_fixed(-2.25, 1) == "-2.2");
}

TEST_CASE("CSV fields are quoted only when they must be, with quotes doubled") {
  CHECK(csv_field("p017") == "p017");
  CHECK(csv_field("a,b") == "\"a,b\"");
  CHECK(csv_field("say \"hi\"") == "\"say \"\"hi\"\"\"");
  CHECK(csv_field("two\nlines") == "\"two\nlines\"");
}

TEST_CASE("HTML and Markdown escaping leave no markup a string could start") {
  CHECK(html_escape("<a href='x'>&\"</a>") == "&lt;a href=&#39;x&#39;&gt;&amp;&quot;&lt;/a&gt;");
  CHECK(markdown_escape("a|b") == "a\\|b");
  CHECK(markdown_escape("[x](javascript:y)") == "\\[x\\]\\(javascript\\:y\\)");
  CHECK(markdown_escape("<b>\n_i_") == "\\<b\\> \\_i\\_");
  CHECK(markdown_escape("p017") == "p017");
}

TEST_CASE("the command line takes one or more data folders, an optional out folder, and help") {
  CliError error;
  auto options = parse_cli({"data"}, error);
  REQUIRE(options.has_value());
  CHECK(options->data_dirs == std::vector<std::filesystem::path>{"data"});
  CHECK(options->out_dir == std::filesystem::path("data") / "report");
  options = parse_cli({"--out", "elsewhere", "data"}, error);
  REQUIRE(options.has_value());
  CHECK(options->out_dir == "elsewhere");
  options = parse_cli({"data", "--out=x"}, error);
  REQUIRE(options.has_value());
  CHECK(options->out_dir == "x");
  options = parse_cli({"--", "-odd-name"}, error);
  REQUIRE(options.has_value());
  CHECK(options->data_dirs == std::vector<std::filesystem::path>{"-odd-name"});
  // Several hosts' folders: the report goes to the first one's report/ unless --out says otherwise.
  options = parse_cli({"h1", "h2", "store"}, error);
  REQUIRE(options.has_value());
  CHECK(options->data_dirs == std::vector<std::filesystem::path>{"h1", "h2", "store"});
  CHECK(options->out_dir == std::filesystem::path("h1") / "report");
  options = parse_cli({"data", "--help"}, error);
  REQUIRE(options.has_value());
  CHECK(options->help);

  CHECK_FALSE(parse_cli({}, error).has_value());
  CHECK(error.message == "DATA_DIR is missing");
  CHECK_FALSE(parse_cli({"a", ""}, error).has_value());
  CHECK(error.message == "a DATA_DIR is empty");
  CHECK_FALSE(parse_cli({"data", "--out"}, error).has_value());
  CHECK(error.message == "--out needs a value");
  CHECK_FALSE(parse_cli({"data", "--verbose"}, error).has_value());
  CHECK(error.message == "unknown argument '--verbose'");
  CHECK_THAT(usage_text(), Catch::Contains("usage: sim_report [OPTIONS] [DATA_DIR...]"));
  CHECK_THAT(usage_text(), Catch::Contains("--out DIR"));
}

TEST_CASE("the command line takes the log's level names for --log-level, info by default") {
  CliError error;
  CHECK(parse_cli({"data"}, error)->log_level == "info");
  const auto options = parse_cli({"data", "--log-level", "debug"}, error);
  REQUIRE(options.has_value());
  CHECK(options->log_level == "debug");
  CHECK_FALSE(parse_cli({"data", "--log-level", "loud"}, error).has_value());
  CHECK(error.message == "bad value 'loud' for --log-level (expected error, warn, info or debug)");
  CHECK_THAT(usage_text(), Catch::Contains("--log-level error|warn|info|debug"));
}

TEST_CASE("the progress bar redraws one line on a terminal and prints a line per tenth in a log") {
  ProgressBar terminal(40, true);
  CHECK(terminal.step(1, 0.0) == "\r[" + std::string(30, '.') + "] 1/40 sessions");
  CHECK(terminal.step(20, 0.0) == "\r[" + std::string(15, '#') + std::string(15, '.') + "] 20/40 sessions");
  CHECK(terminal.step(20, 0.0).empty());  // nothing changed
  CHECK(terminal.finish() == "\n");

  ProgressBar log(100, false);
  std::vector<std::string> lines;
  for (std::size_t done = 1; done <= 100; ++done) {
    const std::string line = log.step(done, 0.0);
    if (!line.empty()) lines.push_back(line);
  }
  REQUIRE(lines.size() == 11);  // 0 % (the first session), then 10 %, 20 %, ..., 100 %
  CHECK(lines[1] == "10/100 sessions (10 %)");
  CHECK(lines.back() == "100/100 sessions (100 %)");
  CHECK(log.finish().empty());

  ProgressBar small(5, true);
  CHECK(small.step(1, 0.1).empty());  // a few sessions need no bar ...
  CHECK_FALSE(small.step(2, 5.0).empty());  // ... unless they take long
}

TEST_CASE("path simplification keeps the ends and the corners and drops points on straight runs") {
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i <= 10; ++i) points.emplace_back(0.1 * i, 0.0);  // a straight run to (1, 0)
  for (int i = 1; i <= 10; ++i) points.emplace_back(1.0, 0.1 * i);  // a corner, then up to (1, 1)
  const auto simple = simplify_path(points, 0.01);
  REQUIRE(simple.size() == 3);
  CHECK(simple[1].isApprox(Eigen::Vector2d(1.0, 0.0)));
  CHECK(simple[2].isApprox(Eigen::Vector2d(1.0, 1.0)));
  CHECK(simplify_path({}, 0.01).empty());
}

TEST_CASE("Hall-zone bins count each session once per zone in 10-point bins") {
  SessionMetrics a, b, none;
  a.robot = RobotMetrics{};
  a.robot->pct_intimate = 0.0;
  a.robot->pct_personal = 15.0;
  a.robot->pct_social = 85.0;
  a.robot->pct_public = 0.0;
  b.robot = RobotMetrics{};
  b.robot->pct_public = 100.0;
  const ZoneBins bins = zone_bins({&a, &b, &none});
  CHECK(bins[0][0] == 2);
  CHECK(bins[1][1] == 1);
  CHECK(bins[2][8] == 1);
  CHECK(bins[3][9] == 1);  // 100 % falls in the last bin
  CHECK(bins[3][0] == 1);
  CHECK(zone_histogram_svg(bins).rfind("<svg", 0) == 0);
}

TEST_CASE("docs/report.md defines every column of sessions.csv, summary.csv and pairs.csv") {
  std::ifstream in(std::string(RFBSIM_SOURCE_DIR) + "/docs/report.md");
  REQUIRE(in.good());
  std::stringstream text;
  text << in.rdbuf();
  const std::string docs = text.str();
  for (const Column& c : session_columns()) {
    INFO(c.name);
    CHECK(docs.find("`" + c.name + "`") != std::string::npos);
  }
  for (const Rate& r : summary_rates()) {
    INFO(r.name);
    CHECK(docs.find("`pct_" + r.name + "`") != std::string::npos);
  }
  CHECK(docs.find("`excluded_sessions`") != std::string::npos);
  CHECK(docs.find("`video_sessions`") != std::string::npos);
  CHECK(summary_csv_header().size() == 5 + summary_rates().size() + 3 * summarized_columns().size());
  // pairs.csv's own columns; its source_<column> ones are sessions.csv's, defined above.
  for (const PairColumn& c : pair_columns()) {
    if (c.name.rfind("source_", 0) == 0 && c.name != "source_session" && c.name != "source_uid" &&
        c.name != "source_folder" && c.name != "source_outcome" && c.name != "source_in_statistics") {
      continue;
    }
    INFO(c.name);
    CHECK(docs.find("`" + c.name + "`") != std::string::npos);
  }
}
