// SPDX-License-Identifier: GPL-2.0-or-later
// The choice of a watcher's source session.
#include "sessions/yoking.hpp"

#include <algorithm>
#include <map>
#include <set>

namespace rfbsim::manager {

namespace {

// Sources in the order they may be taken: earliest end first, the lower id on a tie.
bool ended_earlier(const Session* a, const Session* b) {
  if (a->ended_at != b->ended_at) return a->ended_at < b->ended_at;
  return a->id < b->id;
}

}  // namespace

bool may_be_shown(const Session& session, const std::string& host_id) {
  return session.condition == "interactive" && session.host_id == host_id && session.spent_at.has_value() &&
         session.ended_at.has_value() && counts_as_completed(session.state) && !session.data_path.empty();
}

bool holds_watch_place(const Session& session) {
  return session.condition == "video" && session.yoked_to > 0 &&
         (is_live(session.state) || counts_as_completed(session.state));
}

YokeChoice choose_yoke_source(const std::vector<Session>& sessions, const YokeRequest& request,
                              const std::function<bool(const Session&)>& recording_present) {
  std::map<std::int64_t, const Session*> shown_by_id;  // every session that may be shown, any scenario
  std::vector<const Session*> sources;                 // of the link's scenario, in the order they are taken
  std::vector<const Session*> watchers;                // video sessions holding a place, by id
  for (const Session& session : sessions) {
    if (may_be_shown(session, request.host_id)) {
      shown_by_id[session.id] = &session;
      // A participant who also walked is never shown their own walk.
      if (session.scenario == request.scenario && session.uid != request.watcher_uid) sources.push_back(&session);
    } else if (holds_watch_place(session)) {
      watchers.push_back(&session);
    }
  }
  std::sort(sources.begin(), sources.end(), ended_earlier);
  std::sort(watchers.begin(), watchers.end(), [](const Session* a, const Session* b) { return a->id < b->id; });

  // Places taken, by others: the watcher's own earlier sessions do not count against what they are shown again.
  std::map<std::int64_t, int> taken;
  for (const Session* watcher : watchers) {
    if (watcher->uid != request.watcher_uid) ++taken[watcher->yoked_to];
  }
  // Each folder is looked at once per choice: the walkers' loops below may ask of a source several times.
  std::map<std::int64_t, bool> present;
  const auto on_disk = [&](const Session& source) {
    const auto known = present.find(source.id);
    return known != present.end() ? known->second : present[source.id] = recording_present(source);
  };
  const auto has_room = [&](const Session* source) { return taken[source->id] < request.max_viewers && on_disk(*source); };
  const auto first_of = [&](const std::string& walker) -> const Session* {
    for (const Session* source : sources) {
      if (source->uid == walker && has_room(source)) return source;
    }
    return nullptr;
  };
  YokeChoice choice;

  // Shown this scenario before: the same session again.
  for (const Session* watcher : watchers) {
    if (watcher->uid != request.watcher_uid || watcher->scenario != request.scenario) continue;
    const auto source = shown_by_id.find(watcher->yoked_to);
    if (source != shown_by_id.end() && on_disk(*source->second)) {
      choice.source = *source->second;
      return choice;
    }
  }

  if (!request.pinned_uid.empty()) {
    if (const Session* source = first_of(request.pinned_uid)) {
      choice.source = *source;
    } else {
      choice.why_none = "the link's yoke_uid " + request.pinned_uid + " has no session of scenario " + request.scenario +
                        " that may be shown with fewer than " + std::to_string(request.max_viewers) + " watchers";
    }
    return choice;
  }

  if (request.by_participant) {
    // Pairings, from the rows: a watcher's walker is the one of their earliest video session holding its place.
    std::map<std::string, std::string> walker_of;
    for (const Session* watcher : watchers) {
      const auto source = shown_by_id.find(watcher->yoked_to);
      if (source != shown_by_id.end()) walker_of.emplace(watcher->uid, source->second->uid);
    }
    if (const auto paired = walker_of.find(request.watcher_uid); paired != walker_of.end()) {
      if (const Session* source = first_of(paired->second)) {
        choice.source = *source;
      } else {
        choice.why_none = "the walker this watcher is paired with has no session of scenario " + request.scenario +
                          " that may be shown (yet, or with room)";
      }
      return choice;
    }
    std::map<std::string, std::set<std::string>> paired_with;  // walker -> their other watchers
    for (const auto& [watcher, walker] : walker_of) {
      if (watcher != request.watcher_uid) paired_with[walker].insert(watcher);
    }
    std::set<std::string> tried;
    for (const Session* candidate : sources) {
      if (!tried.insert(candidate->uid).second) continue;
      if (static_cast<int>(paired_with[candidate->uid].size()) >= request.max_viewers) continue;
      if (const Session* source = first_of(candidate->uid)) {
        choice.source = *source;
        return choice;
      }
    }
    choice.why_none = "no walker with a session of scenario " + request.scenario + " has fewer than " +
                      std::to_string(request.max_viewers) + " paired watchers and a session with room";
    return choice;
  }

  for (const Session* source : sources) {
    if (has_room(source)) {
      choice.source = *source;
      return choice;
    }
  }
  choice.why_none = sources.empty() ? "no interactive session of scenario " + request.scenario +
                                          " has ended with its link spent on this host yet"
                                    : "every ended session of scenario " + request.scenario + " already has " +
                                          std::to_string(request.max_viewers) + " watcher(s)";
  return choice;
}

}  // namespace rfbsim::manager
