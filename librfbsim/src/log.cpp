// SPDX-License-Identifier: GPL-2.0-or-later
#include "rfbsim/log.hpp"

#include <atomic>
#include <cstdarg>
#include <cstdio>
#include <map>
#include <mutex>

namespace rfbsim::log {

namespace {

// Which kind of line is how far into its budget, and since when.
struct KindState {
  std::chrono::steady_clock::time_point period_start;
  int written = 0;
  long long suppressed = 0;
  std::string tag;
};

struct Sink {
  std::mutex mutex;
  std::function<void(std::string_view)> sink;
  RateLimit limit;
  std::map<std::string, KindState, std::less<>> kinds;
};

Sink& state() {
  static Sink sink;
  return sink;
}

std::atomic<int> current_level{static_cast<int>(Level::kInfo)};

// One whole line out, under the mutex so that lines of different threads never interleave.
void emit_locked(Sink& sink, std::string_view tag, std::string_view text) {
  std::string line;
  line.reserve(tag.size() + text.size() + 4);
  line.append("[").append(tag).append("] ").append(text);
  if (sink.sink) {
    sink.sink(line);
    return;
  }
  line.push_back('\n');
  std::fwrite(line.data(), 1, line.size(), stderr);
}

std::string formatted(const char* format, va_list args) {
  va_list copy;
  va_copy(copy, args);
  char small[512];
  const int length = std::vsnprintf(small, sizeof small, format, copy);
  va_end(copy);
  if (length < 0) return format;
  std::string text;
  if (static_cast<std::size_t>(length) < sizeof small) {
    text.assign(small, static_cast<std::size_t>(length));
  } else {
    text.resize(static_cast<std::size_t>(length) + 1);
    std::vsnprintf(text.data(), text.size(), format, args);
    text.resize(static_cast<std::size_t>(length));
  }
  // A format's own trailing newline (the fprintf habit) would make an empty line: the sink ends each line.
  while (!text.empty() && text.back() == '\n') text.pop_back();
  return text;
}

void write_suppressed_locked(Sink& sink, const std::string& kind, KindState& state) {
  if (state.suppressed == 0) return;
  emit_locked(sink, state.tag, std::to_string(state.suppressed) + " more like this suppressed (" + kind + ")");
  state.suppressed = 0;
}

}  // namespace

void set_level(Level level) { current_level.store(static_cast<int>(level)); }
Level level() { return static_cast<Level>(current_level.load()); }
bool enabled(Level level) { return static_cast<int>(level) <= current_level.load(); }

bool parse_level(std::string_view text, Level& out) {
  for (int i = 0; i < 4; ++i) {
    if (text == kLevelNames[i]) {
      out = static_cast<Level>(i);
      return true;
    }
  }
  return false;
}

bool set_level(std::string_view name) {
  Level named{};
  if (!parse_level(name, named)) return false;
  set_level(named);
  return true;
}

void write(Level level, std::string_view tag, std::string_view text) {
  if (!enabled(level)) return;
  Sink& sink = state();
  std::lock_guard<std::mutex> lock(sink.mutex);
  emit_locked(sink, tag, text);
}

namespace {

void vwrite(Level level, const char* tag, const char* format, va_list args) {
  if (enabled(level)) write(level, tag, formatted(format, args));
}

}  // namespace

#define RFBSIM_LOG_AT(name, lvl)                    \
  void name(const char* tag, const char* format, ...) { \
    va_list args;                                   \
    va_start(args, format);                         \
    vwrite(lvl, tag, format, args);                 \
    va_end(args);                                   \
  }
RFBSIM_LOG_AT(error, Level::kError)
RFBSIM_LOG_AT(warn, Level::kWarn)
RFBSIM_LOG_AT(info, Level::kInfo)
RFBSIM_LOG_AT(debug, Level::kDebug)
#undef RFBSIM_LOG_AT

void set_rate_limit(RateLimit limit) {
  Sink& sink = state();
  std::lock_guard<std::mutex> lock(sink.mutex);
  sink.limit = limit;
}

void limited(Level level, const char* kind, const char* tag, const char* format, ...) {
  if (!enabled(level)) return;
  const auto now = std::chrono::steady_clock::now();
  Sink& sink = state();
  std::unique_lock<std::mutex> lock(sink.mutex);
  auto it = sink.kinds.find(kind);
  if (it == sink.kinds.end()) it = sink.kinds.emplace(kind, KindState{now, 0, 0, tag}).first;
  KindState& kind_state = it->second;
  if (now - kind_state.period_start >= sink.limit.period) {
    write_suppressed_locked(sink, it->first, kind_state);
    kind_state.period_start = now;
    kind_state.written = 0;
  }
  if (kind_state.written >= sink.limit.lines) {
    ++kind_state.suppressed;
    return;
  }
  ++kind_state.written;
  lock.unlock();  // formatting needs no lock
  va_list args;
  va_start(args, format);
  const std::string text = formatted(format, args);
  va_end(args);
  lock.lock();
  emit_locked(sink, tag, text);
}

void flush_suppressed() {
  Sink& sink = state();
  std::lock_guard<std::mutex> lock(sink.mutex);
  for (auto& [kind, kind_state] : sink.kinds) write_suppressed_locked(sink, kind, kind_state);
}

void set_sink(std::function<void(std::string_view line)> sink_function) {
  Sink& sink = state();
  std::lock_guard<std::mutex> lock(sink.mutex);
  sink.sink = std::move(sink_function);
}

}  // namespace rfbsim::log
