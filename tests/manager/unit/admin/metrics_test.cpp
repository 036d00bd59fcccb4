// SPDX-License-Identifier: GPL-2.0-or-later
#include <catch2/catch.hpp>

#include <sstream>

#include "admin/metrics.hpp"

using rfbsim::manager::Metrics;
using rfbsim::manager::Rejection;
using rfbsim::manager::RelayCounts;
using rfbsim::manager::RelayKind;
using rfbsim::manager::rejection_name;
using rfbsim::manager::SessionState;
using rfbsim::manager::SessionStream;
using rfbsim::manager::StreamReport;

namespace {

// The lines of the exposition that start with `prefix`, in order.
std::vector<std::string> lines_starting(const std::string& text, const std::string& prefix) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(prefix, 0) == 0) out.push_back(line);
  }
  return out;
}

bool has_line(const std::string& text, const std::string& line) {
  return ("\n" + text).find("\n" + line + "\n") != std::string::npos;
}

}  // namespace

TEST_CASE("a new Metrics renders every series at zero") {
  const Metrics metrics;
  const std::string text = metrics.render({}, 4, {});
  CHECK(text.back() == '\n');
  CHECK(has_line(text, "rfbsim_session_capacity 4"));
  CHECK(has_line(text, "rfbsim_session_starts_total 0"));
  CHECK(has_line(text, "rfbsim_session_startup_seconds_count 0"));
  CHECK(has_line(text, "rfbsim_session_startup_seconds_sum 0"));
  CHECK(has_line(text, "rfbsim_relay_connections{kind=\"participant\"} 0"));
  CHECK(has_line(text, "rfbsim_relay_connections{kind=\"watch\"} 0"));
  CHECK(has_line(text, "rfbsim_relay_connections_total{kind=\"participant\"} 0"));
  CHECK(has_line(text, "rfbsim_relay_connections_total{kind=\"watch\"} 0"));
  CHECK(has_line(text, "rfbsim_relay_bytes_total{direction=\"to_client\"} 0"));
  CHECK(has_line(text, "rfbsim_relay_bytes_total{direction=\"to_session\"} 0"));
}

TEST_CASE("every series has its HELP and TYPE") {
  const std::string text = Metrics().render({}, 1, {});
  CHECK(lines_starting(text, "# TYPE ") == std::vector<std::string>{
                                               "# TYPE rfbsim_sessions gauge",
                                               "# TYPE rfbsim_session_capacity gauge",
                                               "# TYPE rfbsim_session_starts_total counter",
                                               "# TYPE rfbsim_session_startup_seconds histogram",
                                               "# TYPE rfbsim_relay_bytes_total counter",
                                               "# TYPE rfbsim_relay_connections gauge",
                                               "# TYPE rfbsim_relay_connections_total counter",
                                               "# TYPE rfbsim_rejections_total counter",
                                               "# TYPE rfbsim_takeovers_total counter",
                                               "# TYPE rfbsim_pong_timeouts_total counter",
                                               "# TYPE rfbsim_accept_errors_total counter",
      "# TYPE rfbsim_index_write_errors_total counter",
                                               "# TYPE rfbsim_connections gauge",
                                               "# TYPE rfbsim_connection_addresses gauge",
                                               "# TYPE rfbsim_session_rtt_ms gauge",
                                               "# TYPE rfbsim_session_fps gauge",
                                               "# TYPE rfbsim_session_quality gauge",
                                               "# TYPE rfbsim_session_codec_info gauge",
                                           });
  CHECK(lines_starting(text, "# HELP ").size() == 18);
}

TEST_CASE("sessions are listed for every state, zero included") {
  const Metrics metrics;
  const std::string text =
      metrics.render({{SessionState::kRunning, 2}, {SessionState::kFinished, 17}, {SessionState::kCrashed, 1}}, 4, {});
  CHECK(lines_starting(text, "rfbsim_sessions{") == std::vector<std::string>{
                                                        "rfbsim_sessions{state=\"starting\"} 0",
                                                        "rfbsim_sessions{state=\"running\"} 2",
                                                        "rfbsim_sessions{state=\"ending\"} 0",
                                                        "rfbsim_sessions{state=\"finished\"} 17",
                                                        "rfbsim_sessions{state=\"expired\"} 0",
                                                        "rfbsim_sessions{state=\"idle\"} 0",
                                                        "rfbsim_sessions{state=\"ended\"} 0",
                                                        "rfbsim_sessions{state=\"shutdown\"} 0",
                                                        "rfbsim_sessions{state=\"crashed\"} 1",
                                                        "rfbsim_sessions{state=\"failed\"} 0",
                                                        "rfbsim_sessions{state=\"interrupted\"} 0",
                                                        "rfbsim_sessions{state=\"abandoned\"} 0",
                                                    });
}

TEST_CASE("the start-up histogram's buckets are cumulative") {
  Metrics metrics;
  metrics.observe_startup(0.15);
  metrics.observe_startup(0.6);
  const std::string text = metrics.render({}, 4, {});
  CHECK(lines_starting(text, "rfbsim_session_startup_seconds") == std::vector<std::string>{
            "rfbsim_session_startup_seconds_bucket{le=\"0.1\"} 0",
            "rfbsim_session_startup_seconds_bucket{le=\"0.2\"} 1",
            "rfbsim_session_startup_seconds_bucket{le=\"0.3\"} 1",
            "rfbsim_session_startup_seconds_bucket{le=\"0.5\"} 1",
            "rfbsim_session_startup_seconds_bucket{le=\"0.75\"} 2",
            "rfbsim_session_startup_seconds_bucket{le=\"1\"} 2",
            "rfbsim_session_startup_seconds_bucket{le=\"2\"} 2",
            "rfbsim_session_startup_seconds_bucket{le=\"5\"} 2",
            "rfbsim_session_startup_seconds_bucket{le=\"10\"} 2",
            "rfbsim_session_startup_seconds_bucket{le=\"30\"} 2",
            "rfbsim_session_startup_seconds_bucket{le=\"+Inf\"} 2",
            "rfbsim_session_startup_seconds_sum 0.75",
            "rfbsim_session_startup_seconds_count 2",
        });
}

TEST_CASE("a start-up time on a bucket's bound counts in that bucket, one beyond the last only in +Inf") {
  Metrics metrics;
  metrics.observe_startup(0.1);
  metrics.observe_startup(31);
  const std::string text = metrics.render({}, 4, {});
  CHECK(has_line(text, "rfbsim_session_startup_seconds_bucket{le=\"0.1\"} 1"));
  CHECK(has_line(text, "rfbsim_session_startup_seconds_bucket{le=\"30\"} 1"));
  CHECK(has_line(text, "rfbsim_session_startup_seconds_bucket{le=\"+Inf\"} 2"));
  CHECK(has_line(text, "rfbsim_session_startup_seconds_sum 31.1"));
}

TEST_CASE("counters count") {
  Metrics metrics;
  metrics.count_start();
  metrics.count_start();
  metrics.count_start();
  metrics.add_bytes_to_client(1000);
  metrics.add_bytes_to_client(24);
  metrics.add_bytes_to_session(5);
  metrics.count_relay_open(RelayKind::kParticipant);
  metrics.count_relay_open(RelayKind::kWatch);
  metrics.count_relay_open(RelayKind::kWatch);
  CHECK(metrics.starts() == 3);
  CHECK(metrics.bytes_to_client() == 1024);
  const std::string text = metrics.render({}, 8, RelayCounts{1, 2});
  CHECK(has_line(text, "rfbsim_session_starts_total 3"));
  CHECK(has_line(text, "rfbsim_session_capacity 8"));
  CHECK(has_line(text, "rfbsim_relay_bytes_total{direction=\"to_client\"} 1024"));
  CHECK(has_line(text, "rfbsim_relay_bytes_total{direction=\"to_session\"} 5"));
  // A researcher watching is counted apart from participants.
  CHECK(has_line(text, "rfbsim_relay_connections{kind=\"participant\"} 1"));
  CHECK(has_line(text, "rfbsim_relay_connections{kind=\"watch\"} 2"));
  CHECK(has_line(text, "rfbsim_relay_connections_total{kind=\"participant\"} 1"));
  CHECK(has_line(text, "rfbsim_relay_connections_total{kind=\"watch\"} 2"));
}

TEST_CASE("rejections are counted by reason and every reason is listed") {
  Metrics metrics;
  metrics.count_rejection(Rejection::kBusy);
  metrics.count_rejection(Rejection::kBusy);
  metrics.count_rejection(Rejection::kBadSignature);
  metrics.count_rejection(Rejection::kStartFailed);
  CHECK(metrics.rejections(Rejection::kBusy) == 2);
  CHECK(metrics.rejections(Rejection::kBadSignature) == 1);
  CHECK(metrics.rejections(Rejection::kUnauthorized) == 0);
  CHECK(lines_starting(metrics.render({}, 4, {}), "rfbsim_rejections_total{") == std::vector<std::string>{
            "rfbsim_rejections_total{reason=\"busy\"} 2",
            "rfbsim_rejections_total{reason=\"bad_request\"} 0",
            "rfbsim_rejections_total{reason=\"bad_signature\"} 1",
            "rfbsim_rejections_total{reason=\"already_completed\"} 0",
            "rfbsim_rejections_total{reason=\"unknown_session\"} 0",
            "rfbsim_rejections_total{reason=\"ended_session\"} 0",
            "rfbsim_rejections_total{reason=\"forbidden_origin\"} 0",
            "rfbsim_rejections_total{reason=\"unauthorized\"} 0",
            "rfbsim_rejections_total{reason=\"start_failed\"} 1",
            "rfbsim_rejections_total{reason=\"rate_limited\"} 0",
            "rfbsim_rejections_total{reason=\"connection_limit\"} 0",
            "rfbsim_rejections_total{reason=\"unspent_limit\"} 0",
            "rfbsim_rejections_total{reason=\"head_preview\"} 0",
            "rfbsim_rejections_total{reason=\"cannot_record\"} 0",
            "rfbsim_rejections_total{reason=\"no_recording\"} 0",
        });
}

TEST_CASE("rejection reasons have their label names") {
  CHECK(std::string(rejection_name(Rejection::kCompleted)) == "already_completed");
  CHECK(std::string(rejection_name(Rejection::kForbiddenOrigin)) == "forbidden_origin");
}

TEST_CASE("each watched session's stream is a series labelled with its id, and only what is known") {
  const Metrics metrics;
  const std::vector<SessionStream> streams = {
      {12, StreamReport{1, "h264", 52.3, 29.7, 80, std::nullopt}},
      {3, StreamReport{2, "tight", std::nullopt, 15, 60, std::nullopt}},  // a client without fences: no round trip
      {7, StreamReport{0, "tight", 10, 30, 80, std::nullopt}},            // nobody watches any more: no series
  };
  const std::string text = metrics.render({}, 4, {}, streams);
  CHECK(lines_starting(text, "rfbsim_session_rtt_ms{") == std::vector<std::string>{
                                                             "rfbsim_session_rtt_ms{session=\"12\"} 52.3",
                                                         });
  CHECK(lines_starting(text, "rfbsim_session_fps{") == std::vector<std::string>{
                                                          "rfbsim_session_fps{session=\"12\"} 29.7",
                                                          "rfbsim_session_fps{session=\"3\"} 15",
                                                      });
  CHECK(lines_starting(text, "rfbsim_session_codec_info{") ==
        std::vector<std::string>{
            "rfbsim_session_codec_info{session=\"12\",codec=\"h264\"} 1",
            "rfbsim_session_codec_info{session=\"3\",codec=\"tight\"} 1",
        });
  // Without streams the metrics are announced and have no series.
  const std::string none = metrics.render({}, 4, {});
  CHECK(has_line(none, "# TYPE rfbsim_session_rtt_ms gauge"));
  CHECK(lines_starting(none, "rfbsim_session_rtt_ms{").empty());
  CHECK(lines_starting(none, "rfbsim_session_codec_info{").empty());
}

TEST_CASE("a label value that is not plain cannot break the exposition text") {
  const std::string text = Metrics().render({}, 4, {}, {{5, StreamReport{1, "a\"b\\c\nd", 1, 1, 1, std::nullopt}}});
  CHECK(has_line(text, R"(rfbsim_session_codec_info{session="5",codec="a\"b\\c\nd"} 1)"));
}
