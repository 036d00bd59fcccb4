// SPDX-License-Identifier: GPL-2.0-or-later
// The video condition: watchers' rows and their pairs.
#include "video_pairs.hpp"

#include <algorithm>
#include <tuple>
#include <utility>

#include "manager_record.hpp"
#include "participation.hpp"
#include "watcher_session.hpp"

namespace rfbsim::report {

namespace {

using M = SessionMetrics;

Value id_cell(const std::optional<std::int64_t>& id) { return id ? Value(*id) : Value(); }

// A session as a warning names it: its folder, uid and host.
std::string named(const M& m) { return m.folder + " (uid '" + m.uid + "', host " + m.host + ")"; }

// Why `watcher` has no source among `sessions`, or "" with `source` set to the one it watched.
std::string find_source(const std::vector<M>& sessions, const M& watcher, std::size_t& source) {
  const WatcherMetrics& w = *watcher.watcher;
  if (!w.yoked_to) return "watcher " + named(watcher) + " watched a recording sim_rfb was given by hand (yoked_to " +
                          "null): no pair";
  const std::string what = "watcher " + named(watcher) + " watched session " + std::to_string(*w.yoked_to) +
                           " on host " + watcher.host;
  // The session of that id on the watcher's host, among the interactive ones.
  std::vector<std::size_t> same_id;
  for (std::size_t i = 0; i < sessions.size(); ++i) {
    const M& m = sessions[i];
    if (!m.video() && m.host == watcher.host && m.session_id == w.yoked_to) same_id.push_back(i);
  }
  if (same_id.empty()) return what + ", which is not in the data: no pair";
  // A host's ids start again when its index is reset: the start time tells the session watched from another.
  std::vector<std::size_t> matching;
  for (const std::size_t i : same_id) {
    if (w.source_started_at.empty() || sessions[i].started_at == w.source_started_at) matching.push_back(i);
  }
  if (matching.empty()) {
    return what + ", which is not " + named(sessions[same_id.front()]) + " (that one started at " +
           sessions[same_id.front()].started_at + ", the one watched at " + w.source_started_at + "): no pair";
  }
  if (matching.size() > 1) {
    std::string folders;
    for (const std::size_t i : matching) folders += (folders.empty() ? "" : ", ") + sessions[i].folder;
    return what + ", which matches " + std::to_string(matching.size()) + " sessions (" + folders + "): no pair";
  }
  source = matching.front();
  return "";
}

PairColumn pair_column(const char* name, const char* unit, const char* meaning,
                       std::function<Value(const VideoPair&, const M&, const M&)> value, bool shown = false) {
  return PairColumn{name, unit, meaning, std::move(value), shown};
}

std::vector<PairColumn> make_pair_columns() {
  // name, unit, meaning, value, shown
  std::vector<PairColumn> columns = {
      pair_column("pair", "", "the pair's number",
                  [](const VideoPair& p, const M&, const M&) { return Value(static_cast<std::int64_t>(p.number)); },
                  true),
      pair_column("host", "", "the host both ran on",
                  [](const VideoPair&, const M& a, const M&) { return Value(a.host); }, true),
      pair_column("scenario", "", "the source's scenario",
                  [](const VideoPair&, const M& a, const M&) { return Value(a.scenario); }, true),
      pair_column("source_session", "", "the source's (A's) session id",
                  [](const VideoPair&, const M& a, const M&) { return id_cell(a.session_id); }, true),
      pair_column("source_uid", "", "the source's participant id",
                  [](const VideoPair&, const M& a, const M&) { return Value(a.uid); }, true),
      pair_column("source_folder", "", "the source's folder, as in sessions.csv",
                  [](const VideoPair&, const M& a, const M&) { return Value(a.folder); }),
      pair_column("watcher_session", "", "the watcher's (B's) session id",
                  [](const VideoPair&, const M&, const M& b) { return id_cell(b.session_id); }, true),
      pair_column("watcher_uid", "", "the watcher's participant id",
                  [](const VideoPair&, const M&, const M& b) { return Value(b.uid); }, true),
      pair_column("watcher_folder", "", "the watcher's folder, as in sessions.csv",
                  [](const VideoPair&, const M&, const M& b) { return Value(b.folder); }),
      pair_column("watcher_outcome", "", "watched (shown to its end), or empty",
                  [](const VideoPair&, const M&, const M& b) { return Value(b.outcome); }, true),
      pair_column("watcher_end_reason", "", "watched, signal or error; empty while watching",
                  [](const VideoPair&, const M&, const M& b) { return Value(b.end_reason); }),
      pair_column("watcher_watched_s", "s", "the watcher's ended_at - started_at",
                  [](const VideoPair&, const M&, const M& b) {
                    return b.watcher->watched_s ? Value(*b.watcher->watched_s) : Value();
                  },
                  true),
      pair_column("watcher_shown_pct", "%", "share of the recording's ticks shown",
                  [](const VideoPair&, const M&, const M& b) {
                    const WatcherMetrics& w = *b.watcher;
                    if (!w.end_tick || !w.source_end_tick || *w.source_end_tick == 0) return Value();
                    return Value(100.0 * static_cast<double>(*w.end_tick) / static_cast<double>(*w.source_end_tick));
                  }),
      pair_column("source_outcome", "", "the source's outcome: completed, timeout or empty",
                  [](const VideoPair&, const M& a, const M&) { return Value(a.outcome); }, true),
      pair_column("source_in_statistics", "", "the source counts in summary.csv (its link was spent)",
                  [](const VideoPair&, const M& a, const M&) { return Value(in_statistics(a)); }),
  };
  // A's measures, exactly as sessions.csv has them.
  for (Column& c : measure_columns()) {
    columns.push_back(PairColumn{"source_" + c.name, c.unit, c.meaning,
                                 [value = std::move(c.value)](const VideoPair&, const M& a, const M&) {
                                   return value(a);
                                 },
                                 false});
  }
  return columns;
}

}  // namespace

SessionMetrics watcher_metrics(const tools::WatcherSession& session) {
  SessionMetrics out;
  out.uid = session.uid;
  out.scenario = session.scenario;
  out.seed = session.source_seed;
  out.started_at = session.started_at;
  out.outcome = session.outcome.value_or("");
  out.end_reason = session.end_reason.value_or("");
  out.ended_cleanly = session.ended_at.has_value();
  WatcherMetrics w;
  w.yoked_to = session.yoked_to;
  w.yoked_to_uid_hash = session.yoked_to_uid_hash;
  w.source_started_at = session.source_started_at;
  w.source_end_tick = session.source_end_tick;
  w.end_tick = session.end_tick;
  w.viewers = session.viewers;
  // Wall-clock seconds from the start of the watching to its end (both sim_rfb's clock, to the millisecond).
  const std::optional<long long> from = parse_utc_millis(session.started_at);
  const std::optional<long long> to = session.ended_at ? parse_utc_millis(*session.ended_at) : std::nullopt;
  if (from && to && *to >= *from) w.watched_s = static_cast<double>(*to - *from) / 1000.0;
  out.watcher = w;
  return out;
}

VideoPairing pair_watchers(const std::vector<SessionMetrics>& sessions) {
  VideoPairing out;
  for (std::size_t i = 0; i < sessions.size(); ++i) {
    if (!sessions[i].video()) continue;
    ++out.watchers;
    std::size_t source = 0;
    const std::string why_not = find_source(sessions, sessions[i], source);
    if (why_not.empty()) {
      out.pairs.push_back({0, source, i});
    } else {
      out.warnings.push_back(why_not);
    }
  }
  // By A's id, then B's (a session without an id last), then the folders, which are unique.
  const auto key = [&](const VideoPair& p) {
    const M& a = sessions[p.source];
    const M& b = sessions[p.watcher];
    return std::make_tuple(!a.session_id, a.session_id.value_or(0), !b.session_id, b.session_id.value_or(0), a.folder,
                           b.folder);
  };
  std::sort(out.pairs.begin(), out.pairs.end(),
            [&](const VideoPair& x, const VideoPair& y) { return key(x) < key(y); });
  for (std::size_t n = 0; n < out.pairs.size(); ++n) out.pairs[n].number = n + 1;
  return out;
}

std::string video_note(const VideoPairing& pairing) {
  const std::size_t unpaired = pairing.watchers - pairing.pairs.size();
  std::string out =
      "Each watcher (B, condition video) watched a live replay of an interactive session (A, its source), and is "
      "paired with it: B's yoked_to is A's session id on the same host. Watchers walked nowhere, so they are not in "
      "the overview, the measures or summary.csv; each row gives A's measures instead. " +
      std::to_string(pairing.watchers) + " watchers' sessions, " + std::to_string(pairing.pairs.size()) + " paired";
  out += unpaired == 0 ? "." : ", " + std::to_string(unpaired) + " not (each under Warnings, with why).";
  return out;
}

std::string video_count(const VideoPairing& pairing) {
  if (pairing.watchers == 0) return "";
  return ", " + std::to_string(pairing.watchers) + " watchers (video condition) counted apart";
}

const std::vector<PairColumn>& pair_columns() {
  static const std::vector<PairColumn> columns = make_pair_columns();
  return columns;
}

Value pair_cell(const PairColumn& column, const VideoPair& pair, const std::vector<SessionMetrics>& sessions) {
  return column.value(pair, sessions[pair.source], sessions[pair.watcher]);
}

}  // namespace rfbsim::report
