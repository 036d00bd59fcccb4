// SPDX-License-Identifier: GPL-2.0-or-later
// The ready pipe: the lines a session's process (sim_rfb, rfbsim_x11_session) writes on the descriptor its
// parent gave it with --ready-fd, and that sim_manager's supervisor reads. One line each, '\n'-terminated:
//
//   ready 5901                       the RFB port listens (sim_rfb with --port)
//   ready unix /run/s/1.sock         the RFB unix socket listens (--unix-socket; rfbsim_x11_session)
//   x11 display 7                    the X display the program runs on (rfbsim_x11_session, after its ready)
//   stream clients=1 ...             the participant's stream (contract/stream_line.hpp has the keys)
//   outcome completed                the task ended: "completed" or "timeout" (once); "watched": a replay
//                                    (sim_rfb --replay) showed its recording to the end
//   data incomplete reason=TEXT      the session's data can no longer be written (once; TEXT is one line)
//
// The writers below give the exact bytes each program writes; parse_ready_line turns a line back into a value
// and refuses anything else, so that the two sides cannot drift. Pure text: the callers own the descriptors.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "contract/stream_line.hpp"

namespace rfbsim::contract {

/// The longest reason the reader keeps of a "data incomplete" line, characters: what the manager stores and
/// shows. The writer does not cut: its reason is already one line of the recorder's own bounded text.
constexpr std::size_t kMaxDataReason = 160;

/// "ready PORT": the session listens on loopback TCP port 1..65535.
struct ReadyPort {
  int port = 0;
};
/// "ready unix PATH": the session listens on the unix socket PATH (non-empty, no control characters).
struct ReadyUnix {
  std::string path;
};
/// "x11 display N": the X display 0..65535 the session's program runs on.
struct X11Display {
  int display = 0;
};
/// "outcome completed" or "outcome timeout": how the task ended; "outcome watched": the watcher of a replay
/// (sim_rfb --replay, the study's video condition) saw the recording to its end.
enum class TaskEnd { kCompleted, kTimeout, kWatched };
struct TaskOutcomeLine {
  TaskEnd end = TaskEnd::kCompleted;
};
/// "data incomplete reason=TEXT": TEXT cut to kMaxDataReason; "unknown" when the line names none.
struct DataIncomplete {
  std::string reason;
};

/// Any one line of the pipe.
using ReadyLine = std::variant<ReadyPort, ReadyUnix, X11Display, StreamReport, TaskOutcomeLine, DataIncomplete>;

/// The outcome of parsing a line: the line's value, or what is wrong with it.
struct ReadyLineParse {
  std::optional<ReadyLine> line;
  std::string error;  ///< empty on success
};

/// "completed", "timeout" or "watched", as the outcome line (and the manager's index) spell it.
const char* task_end_name(TaskEnd end);

/// The writers: each line's exact bytes, newline included.
std::string ready_port_line(int port);
std::string ready_unix_line(const std::string& path);
std::string x11_display_line(int display);
std::string outcome_line(TaskEnd end);
std::string data_incomplete_line(const std::string& reason);
// The stream line's writer is contract::stream_line (contract/stream_line.hpp).

/// Parses one line (without its '\n') into its value; an error for a line of none of the forms above or a
/// malformed one (a port out of range, an outcome other than completed, timeout and watched, a bad stream
/// pair...).
/// A trailing '\r' is refused except on stream lines, as the manager always did. Never throws.
ReadyLineParse parse_ready_line(std::string_view line);

}  // namespace rfbsim::contract
