// SPDX-License-Identifier: GPL-2.0-or-later
// bench_network's tables (see network_report.hpp).
#include "network_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <tuple>

namespace rfbsim::bench {

namespace {

std::string number(double value, int decimals) { return std::isnan(value) ? "-" : fixed(value, decimals); }

// The server's picture as its samples say: "tight q80", "tight q40-80" when the quality moved, "h264".
std::string server_text(const std::vector<StreamSample>& samples) {
  std::string encoding;
  double low = kNaN;
  double high = kNaN;
  for (const StreamSample& s : samples) {
    if (!s.encoding.empty()) encoding = s.encoding;
    if (!std::isnan(s.quality)) {
      low = std::isnan(low) ? s.quality : std::min(low, s.quality);
      high = std::isnan(high) ? s.quality : std::max(high, s.quality);
    }
  }
  if (encoding.empty()) return "-";
  if (encoding != "tight" || std::isnan(low)) return encoding;
  return encoding + " q" + (low == high ? fixed(low, 0) : fixed(low, 0) + "-" + fixed(high, 0));
}

// Median over the samples of what `field` picks (NaNs left out).
template <typename Field>
double sample_median(const std::vector<StreamSample>& samples, Field field) {
  std::vector<double> values;
  for (const StreamSample& s : samples) {
    const double v = field(s);
    if (!std::isnan(v)) values.push_back(v);
  }
  return quantile(values, 0.5);
}

const MatrixCell* find_cell(const std::vector<MatrixCell>& cells, PathKind path, ClientKind client, double cap,
                            int rtt) {
  for (const MatrixCell& c : cells) {
    if (c.path == path && c.client == client && c.cap_mbit == cap && c.rtt_ms == rtt && c.error.empty()) return &c;
  }
  return nullptr;
}

// The (path, client, cap) groups present, in first-seen order, and the RTTs measured.
struct Axes {
  std::vector<std::tuple<PathKind, ClientKind, double>> groups;
  std::vector<int> rtts;
};

Axes axes_of(const std::vector<MatrixCell>& cells) {
  Axes a;
  for (const MatrixCell& c : cells) {
    const auto group = std::make_tuple(c.path, c.client, c.cap_mbit);
    if (std::find(a.groups.begin(), a.groups.end(), group) == a.groups.end()) a.groups.push_back(group);
    if (std::find(a.rtts.begin(), a.rtts.end(), c.rtt_ms) == a.rtts.end()) a.rtts.push_back(c.rtt_ms);
  }
  std::sort(a.rtts.begin(), a.rtts.end());
  return a;
}

}  // namespace

double quantile(std::vector<double> samples, double q) {
  if (samples.empty()) return kNaN;
  std::sort(samples.begin(), samples.end());
  const double position = q * static_cast<double>(samples.size() - 1);
  const auto below = static_cast<std::size_t>(position);
  const std::size_t above = std::min(below + 1, samples.size() - 1);
  return samples[below] + (samples[above] - samples[below]) * (position - static_cast<double>(below));
}

std::string cap_text(double cap_mbit) {
  if (cap_mbit <= 0) return "none";
  return cap_mbit == std::floor(cap_mbit) ? fixed(cap_mbit, 0) : fixed(cap_mbit, 1);
}

void print_matrix(const std::vector<MatrixCell>& cells, PathKind path) {
  Table table({"client", "RTT ms", "cap Mbit/s", "fps", "Mbit/s", "kB/update", "key p50 ms", "key p95 ms",
               "presses (timed out)", "max gap ms", "queue max ms", "server RTT p50", "RTT - base p50", "server",
               "load"},
              1);
  for (const MatrixCell& c : cells) {
    if (c.path != path) continue;
    std::vector<std::string> row{client_name(c.client), std::to_string(c.rtt_ms), cap_text(c.cap_mbit)};
    if (!c.error.empty()) {
      row.push_back("failed: " + c.error);
      table.add_row(std::move(row));
      continue;
    }
    const CellResult& r = c.result;
    const std::vector<double> latencies = r.latencies();
    const double per_update = r.updates > 0 ? static_cast<double>(r.bytes_down) / static_cast<double>(r.updates) : kNaN;
    row.insert(row.end(),
               {fixed(r.fps(), 1), fixed(r.mbit(), 2), number(per_update / 1000.0, 1),
                number(quantile(latencies, 0.5), 0), number(quantile(latencies, 0.95), 0),
                std::to_string(r.presses.size()) + " (" + std::to_string(r.timeouts()) + ")", fixed(r.max_gap_ms, 0),
                fixed(r.max_queue_delay_ms, 0),
                number(sample_median(r.samples, [](const StreamSample& s) { return s.last_rtt_ms; }), 0),
                number(sample_median(r.samples, [](const StreamSample& s) { return s.last_rtt_ms - s.base_rtt_ms; }),
                       0),
                server_text(r.samples), c.load});
    table.add_row(std::move(row));
  }
  table.print();
  for (const MatrixCell& c : cells) {
    if (c.path == path && c.result.decode_errors > 0) {
      std::printf("\nwarning: %s RTT %d cap %s: %llu H.264 pictures did not decode\n", client_name(c.client), c.rtt_ms,
                  cap_text(c.cap_mbit).c_str(), static_cast<unsigned long long>(c.result.decode_errors));
    }
  }
}

void print_ratios(const std::vector<MatrixCell>& cells) {
  const Axes axes = axes_of(cells);
  std::vector<std::string> headings{"path", "client", "cap Mbit/s", "fps at 0 ms"};
  for (int rtt : axes.rtts) {
    if (rtt != 0) headings.push_back(std::to_string(rtt) + " / 0");
  }
  headings.push_back("target (100: >= 0.9, 200: >= 0.8)");
  Table table(headings, 3);
  for (const auto& [path, client, cap] : axes.groups) {
    const MatrixCell* base = find_cell(cells, path, client, cap, 0);
    if (base == nullptr || base->result.fps() <= 0) continue;
    std::vector<std::string> row{path_name(path), client_name(client), cap_text(cap), fixed(base->result.fps(), 1)};
    std::string verdict;
    for (int rtt : axes.rtts) {
      if (rtt == 0) continue;
      const MatrixCell* c = find_cell(cells, path, client, cap, rtt);
      const double ratio = c == nullptr ? kNaN : c->result.fps() / base->result.fps();
      row.push_back(number(ratio, 2));
      if ((rtt == 100 || rtt == 200) && !std::isnan(ratio)) {
        const bool met = ratio >= (rtt == 100 ? 0.9 : 0.8);
        verdict += (verdict.empty() ? "" : ", ") + std::to_string(rtt) + (met ? " met" : " MISSED");
      }
    }
    row.push_back(verdict.empty() ? "-" : verdict);
    table.add_row(std::move(row));
  }
  table.print();
}

void print_latency_and_bytes(const std::vector<MatrixCell>& cells) {
  const Axes axes = axes_of(cells);
  std::vector<std::string> headings{"path", "client", "cap Mbit/s"};
  for (int rtt : axes.rtts) headings.push_back("p50 at " + std::to_string(rtt) + " (- RTT)");
  Table latency(headings, 3);
  for (const auto& [path, client, cap] : axes.groups) {
    std::vector<std::string> row{path_name(path), client_name(client), cap_text(cap)};
    for (int rtt : axes.rtts) {
      const MatrixCell* c = find_cell(cells, path, client, cap, rtt);
      const double p50 = c == nullptr ? kNaN : quantile(c->result.latencies(), 0.5);
      row.push_back(std::isnan(p50) ? "-" : fixed(p50, 0) + " (" + fixed(p50 - rtt, 0) + ")");
    }
    latency.add_row(std::move(row));
  }
  std::printf("Key-to-picture p50 in ms against RTT (in brackets: p50 minus the RTT)\n\n");
  latency.print();

  Table bytes({"path", "RTT ms", "cap Mbit/s", "cu fps", "h264 fps", "fps h264 / cu", "cu Mbit/s", "h264 Mbit/s",
               "bytes/s h264 / cu", "cu kB/update", "h264 kB/update"},
              1);
  for (const auto& [path, client, cap] : axes.groups) {
    if (client != ClientKind::kCu) continue;
    for (int rtt : axes.rtts) {
      const MatrixCell* jpeg = find_cell(cells, path, ClientKind::kCu, cap, rtt);
      const MatrixCell* h264 = find_cell(cells, path, ClientKind::kH264, cap, rtt);
      if (jpeg == nullptr || h264 == nullptr || jpeg->result.updates == 0 || h264->result.updates == 0) continue;
      const CellResult& j = jpeg->result;
      const CellResult& h = h264->result;
      bytes.add_row({path_name(path), std::to_string(rtt), cap_text(cap), fixed(j.fps(), 1), fixed(h.fps(), 1),
                     fixed(h.fps() / j.fps(), 2), fixed(j.mbit(), 2), fixed(h.mbit(), 2), fixed(h.mbit() / j.mbit(), 2),
                     fixed(static_cast<double>(j.bytes_down) / static_cast<double>(j.updates) / 1000.0, 1),
                     fixed(static_cast<double>(h.bytes_down) / static_cast<double>(h.updates) / 1000.0, 1)});
    }
  }
  std::printf("\nH.264 against Tight JPEG (both ContinuousUpdates + Fence), same path, RTT and cap\n\n");
  bytes.print();
}

void print_long_runs(const std::vector<LongRun>& runs, int rtt_ms, double cap_mbit, double part_s) {
  Table table({"path", "client", "seconds", "presses (timed out)", "first: p50 / p90 ms", "last: p50 / p90 ms",
               "first fps", "last fps", "Mbit/s", "queue max ms", "max gap ms", "server"},
              2);
  for (const LongRun& run : runs) {
    std::vector<std::string> row{path_name(run.path), client_name(run.client)};
    if (!run.error.empty()) {
      row.push_back("failed: " + run.error);
      table.add_row(std::move(row));
      continue;
    }
    const CellResult& r = run.result;
    const double late = r.seconds - part_s;
    const auto part = [&](double from, double to) {
      const std::vector<double> l = r.latencies(from, to);
      return std::to_string(l.size()) + ": " + number(quantile(l, 0.5), 0) + " / " + number(quantile(l, 0.9), 0);
    };
    const auto fps = [&](double from, double to) {
      const auto n =
          std::count_if(r.arrivals_s.begin(), r.arrivals_s.end(), [&](double t) { return t >= from && t < to; });
      return fixed(static_cast<double>(n) / (to - from), 1);
    };
    row.insert(row.end(), {fixed(r.seconds, 0),
                           std::to_string(r.presses.size()) + " (" + std::to_string(r.timeouts()) + ")",
                           part(0, part_s), part(late, 1e300), fps(0, part_s), fps(late, r.seconds), fixed(r.mbit(), 2),
                           fixed(r.max_queue_delay_ms, 0), fixed(r.max_gap_ms, 0), server_text(r.samples)});
    table.add_row(std::move(row));
  }
  std::printf("RTT %d ms, cap %s Mbit/s; first = presses in the first %.0f s, last = in the last %.0f s "
              "(n: p50 / p90)\n\n",
              rtt_ms, cap_text(cap_mbit).c_str(), part_s, part_s);
  table.print();
}

void print_traces(const std::string& title, const CellResult& result) {
  std::printf("%s: the server's reports (encoding quality, last / base RTT ms, window kB, held, fps)\n ",
              title.c_str());
  for (const StreamSample& s : result.samples) {
    std::printf(" [%s q%s %s/%s %s %s %s]", s.encoding.c_str(), number(s.quality, 0).c_str(),
                number(s.last_rtt_ms, 0).c_str(),
                number(s.base_rtt_ms, 0).c_str(), number(s.window_bytes / 1000, 0).c_str(),
                number(s.updates_held, 0).c_str(), number(s.fps, 1).c_str());
  }
  std::printf("\n");
  std::printf("%s: MAD of each update against the picture at the press (ms after the press: MAD)\n", title.c_str());
  for (const PressResult& p : result.presses) {
    std::printf("  press at %5.2f s, latency %s:", p.at_s, number(p.latency_ms, 0).c_str());
    for (const auto& [ms, mad] : p.trace) {
      if (mad < 0) {
        std::printf(" %.0f:ref", ms);
      } else {
        std::printf(" %.0f:%.1f", ms, mad);
      }
    }
    std::printf("\n");
  }
}

}  // namespace rfbsim::bench
