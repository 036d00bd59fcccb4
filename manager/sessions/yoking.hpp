// SPDX-License-Identifier: GPL-2.0-or-later
// Yoking (issue 33): which finished interactive session a video-condition link shows its watcher. Pure: the
// sessions are passed in (the index's rows with the writes still queued laid over them) and whether a
// session's recording is still on disk is asked of the caller, so every rule is unit-tested without a file.
//
// The supervisor decides on the manager's one I/O thread and adds the watcher's session to its table and
// write queue before it takes the next /start: two watchers at once never take one place.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "sessions/session.hpp"

namespace rfbsim::manager {

/// What a watcher's link asks for and the study's rules.
struct YokeRequest {
  std::string watcher_uid;
  std::string scenario;
  std::string pinned_uid;       ///< a signed link's yoke_uid: the walker to show; "" = by the policy
  bool by_participant = false;  ///< yoke_policy by_participant (else earliest_ended)
  int max_viewers = 1;          ///< yoke_max_viewers
  std::string host_id;          ///< sources are this host's own
};

/// The outcome: the session to show, or why there is none (for the researcher's log; the participant is told
/// only that no recording is free).
struct YokeChoice {
  std::optional<Session> source;
  std::string why_none;
};

/// Whether `session` may be shown: interactive, of this host, its link spent, ran its course (finished,
/// expired, idle, ended: an administrator's end included), its recording named.
bool may_be_shown(const Session& session, const std::string& host_id);

/// Whether a video session holds its place with its source: live, or ran its course. One that failed,
/// crashed, was interrupted or shut down, or was abandoned (no picture ever reached a browser) frees it.
bool holds_watch_place(const Session& session);

/// Chooses among `sessions` (any order; duplicates by id are not allowed), where `recording_present` says
/// whether a source's folder still holds its recording.
///  - A watcher who was shown a session of this scenario before (a reconnect after a crash, or a repeat where
///    allow_repeat lets them) is shown the same one again, if it may still be shown; it is not counted twice.
///  - pinned_uid: that walker's earliest-ended session of the scenario with room.
///  - by_participant: the watcher is paired with a walker at their first video link (the walker of their
///    earliest video session that holds its place; the pairing lives in those rows), and shown that walker's
///    session of each scenario. Unpaired, they get the first walker, in the order their sessions of the
///    scenario ended, with fewer than max_viewers watchers paired and a session of the scenario with room.
///  - otherwise: the earliest-ended session of the scenario with fewer than max_viewers watchers.
YokeChoice choose_yoke_source(const std::vector<Session>& sessions, const YokeRequest& request,
                              const std::function<bool(const Session&)>& recording_present);

}  // namespace rfbsim::manager
