// SPDX-License-Identifier: GPL-2.0-or-later
// Static web root helpers.
#include "static_files.hpp"

#include <array>
#include <utility>

#include "http_request.hpp"

namespace rfbsim::detail {

std::optional<std::filesystem::path> resolve_static_path(const std::filesystem::path& root,
                                                         std::string_view url_path) {
  std::string decoded;
  if (!percent_decode_path(url_path, decoded)) return std::nullopt;
  if (decoded.empty() || decoded.front() != '/') return std::nullopt;
  if (decoded.find('\\') != std::string::npos) return std::nullopt;

  // Walk the segments ourselves: any ".." is refused outright rather than normalised away.
  std::filesystem::path relative;
  std::string_view rest(decoded);
  while (!rest.empty()) {
    rest.remove_prefix(1);  // the '/'
    const auto slash = rest.find('/');
    const std::string_view segment = rest.substr(0, slash);
    rest = slash == std::string_view::npos ? std::string_view() : rest.substr(slash);
    if (segment.empty() || segment == ".") continue;
    if (segment == "..") return std::nullopt;
    relative /= std::string(segment);
  }
  std::filesystem::path file = root / relative;
  std::error_code ec;
  if (relative.empty() || std::filesystem::is_directory(file, ec)) file /= "index.html";
  return file;
}

std::string_view mime_type_for(const std::filesystem::path& file) {
  static constexpr std::array<std::pair<std::string_view, std::string_view>, 11> kTypes = {{
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".png", "image/png"},
      {".svg", "image/svg+xml"},
      {".ico", "image/x-icon"},
      {".txt", "text/plain; charset=utf-8"},
      {".wasm", "application/wasm"},
      {".map", "application/json"},
  }};
  const std::string extension = file.extension().string();
  for (const auto& [ext, type] : kTypes) {
    if (extension == ext) return type;
  }
  return "application/octet-stream";
}

std::string_view reason_phrase(int status) {
  switch (status) {
    case 200: return "OK";
    case 400: return "Bad Request";
    case 403: return "Forbidden";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 408: return "Request Timeout";
    case 431: return "Request Header Fields Too Large";
    case 500: return "Internal Server Error";
    case 503: return "Service Unavailable";
    default: return "Unknown";
  }
}

std::string response_head(int status, std::string_view content_type, std::size_t body_bytes) {
  std::string head = "HTTP/1.1 " + std::to_string(status) + " " + std::string(reason_phrase(status)) + "\r\n";
  head += "Content-Type: " + std::string(content_type) + "\r\n";
  head += "Content-Length: " + std::to_string(body_bytes) + "\r\n";
  // One request per connection keeps the sniffing model simple: every connection starts fresh.
  head += "Connection: close\r\n";
  head += "Cache-Control: no-cache\r\n";
  head += "X-Content-Type-Options: nosniff\r\n";
  head += "\r\n";
  return head;
}

}  // namespace rfbsim::detail
