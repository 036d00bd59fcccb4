// SPDX-License-Identifier: GPL-2.0-or-later
// Fuzz target: the ready pipe's parser (contract/ready_line.hpp), which reads whatever a session's process writes.
// Invariants: a line parses to a value or to an error, never both; a port, display and stream value is within its
// bounds; and a parsed ready, display, outcome or stream line, written again with the contract's writer, parses to
// the same value.
#include <string>
#include <variant>

#include "contract/ready_line.hpp"
#include "fuzz_check.hpp"

using rfbsim::fuzz::check;
namespace contract = rfbsim::contract;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = rfbsim::fuzz::as_text(data, size);
  const contract::ReadyLineParse parsed = contract::parse_ready_line(text);
  check(parsed.line.has_value() == parsed.error.empty(), "a value and an error, or neither");
  if (!parsed.line) return 0;
  std::string again;
  if (const auto* port = std::get_if<contract::ReadyPort>(&*parsed.line)) {
    check(port->port >= 1 && port->port <= 65535, "port out of range");
    again = contract::ready_port_line(port->port);
  } else if (const auto* display = std::get_if<contract::X11Display>(&*parsed.line)) {
    check(display->display >= 0 && display->display <= 65535, "display out of range");
    again = contract::x11_display_line(display->display);
  } else if (const auto* outcome = std::get_if<contract::TaskOutcomeLine>(&*parsed.line)) {
    again = contract::outcome_line(outcome->end);
  } else if (const auto* stream = std::get_if<contract::StreamReport>(&*parsed.line)) {
    check(stream->clients >= 0 && stream->clients <= contract::kMaxStreamClients, "clients out of range");
    check(stream->codec.empty() || contract::is_codec_name(stream->codec), "codec not a codec name");
    if (stream->clients == 0) return 0;  // the writer writes nothing else then
    again = contract::stream_line(*stream);
  } else {
    return 0;  // ready unix and data incomplete carry text as it came
  }
  again.pop_back();
  const contract::ReadyLineParse reread = contract::parse_ready_line(again);
  check(reread.line.has_value() && reread.line->index() == parsed.line->index(), "written again, read as another line");
  return 0;
}
