// The static file server behind `tailor view` (see http_server.h).
#include "http_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <list>
#include <mutex>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

namespace tailor::cli {
namespace {

constexpr size_t kMaxHeaderBytes = 16 * 1024;  // a GET from a browser is well under 2 KB
constexpr int kPollMillis = 200;               // how often the server and its workers look at the stop flag
constexpr int kHeaderSeconds = 2;              // a client must send its whole request within this (slow or silent ones
                                   // are dropped: a per-recv timeout would let a trickle hold a worker forever)
constexpr int kStallSeconds = 30;            // a client that accepts no byte of the answer for this long is dropped
constexpr size_t kMaxBodyBytes = 16u << 20;  // a POST body (tailor edit: face lists and strokes) at most 16 MiB
constexpr int kBodySeconds = 30;             // a POST body must arrive within this
constexpr size_t kMaxWorkers = 64;           // connections served at once; when full, the oldest one still
                                             // waiting for its request (or a POST's body) is dropped; 503 only
                                             // when none is waiting

// Content-Security-Policy of every answer: scripts, styles, images and fetches from this server only.
// The one inline script, index.html's importmap, is allowed by its SHA-256 (tests/viewer_test.sh
// checks the hash against web/index.html); styles may be inline (index.html's <style> block and
// style attributes); GLTFLoader reads embedded textures through blob: URLs. The meshopt and Draco
// decoders compile WebAssembly ('wasm-unsafe-eval': WebAssembly only, not JavaScript eval) and
// Draco's runs in a worker made from a blob: URL.
constexpr const char* kContentSecurityPolicy =
    "default-src 'none'; script-src 'self' 'sha256-m3Nsq/c0thop7NTHfBJi1BT+HUVzyPDfkQMAS8PG5qw=' "
    "'wasm-unsafe-eval'; worker-src blob:; "
    "style-src 'self' 'unsafe-inline'; img-src 'self' blob: data:; connect-src 'self' blob: data:; "
    "base-uri 'none'; form-action 'none'; frame-ancestors 'none'";

using Clock = std::chrono::steady_clock;

// Waits until fd is ready for `events`, the stop flag is set, or the deadline passes.
bool wait_ready(int fd, short events, const std::atomic<bool>& stop, Clock::time_point deadline) {
  while (!stop.load()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) return false;
    pollfd pfd{fd, events, 0};
    const int ready = ::poll(&pfd, 1, static_cast<int>(std::min<long long>(left, kPollMillis)));
    if (ready > 0) return true;
    if (ready < 0 && errno != EINTR) return false;
  }
  return false;
}

bool send_all(int fd, const char* data, size_t size, const std::atomic<bool>& stop) {
  while (size > 0) {
    if (!wait_ready(fd, POLLOUT, stop, Clock::now() + std::chrono::seconds(kStallSeconds))) return false;
    const ssize_t n = ::send(fd, data, size, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n < 0 && (errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK)) continue;
    if (n <= 0) return false;
    data += n;
    size -= static_cast<size_t>(n);
  }
  return true;
}

void send_status(int fd, int code, const char* reason, const std::atomic<bool>& stop) {
  const std::string body = std::to_string(code) + " " + reason + "\n";
  const std::string head = "HTTP/1.1 " + std::to_string(code) + " " + reason +
                           "\r\nContent-Type: text/plain\r\nContent-Length: " + std::to_string(body.size()) +
                           "\r\nConnection: close\r\n\r\n";
  send_all(fd, (head + body).data(), head.size() + body.size(), stop);
}

const char* reason_phrase(int code) {
  switch (code) {
    case 200: return "OK";
    case 400: return "Bad Request";
    case 403: return "Forbidden";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 409: return "Conflict";
    case 411: return "Length Required";
    case 413: return "Content Too Large";
    case 415: return "Unsupported Media Type";
    case 500: return "Internal Server Error";
    case 503: return "Service Unavailable";
    default: return "Error";
  }
}

std::string header_for(size_t length, const std::string& type, int code = 200,
                       const std::vector<std::pair<std::string, std::string>>& extra = {}) {
  std::string head = "HTTP/1.1 " + std::to_string(code) + " " + reason_phrase(code) + "\r\nContent-Type: " + type +
                     "\r\nContent-Length: " + std::to_string(length) +
                     "\r\nCache-Control: no-cache\r\nX-Content-Type-Options: nosniff\r\nContent-Security-Policy: " +
                     kContentSecurityPolicy + "\r\n";
  for (const auto& [name, value] : extra) head += name + ": " + value + "\r\n";
  return head + "Connection: close\r\n\r\n";
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// The values of header `name` (lower case) in a request head, blanks trimmed, in order (at most
// `most` of them).
std::vector<std::string> header_values(const std::string& request, const std::string& name, size_t most) {
  std::vector<std::string> values;
  size_t pos = request.find("\r\n");
  while (pos != std::string::npos && pos + 2 < request.size() && values.size() < most) {
    const size_t start = pos + 2;
    const size_t end = request.find("\r\n", start);
    if (end == std::string::npos || end == start) break;
    const size_t colon = request.find(':', start);
    if (colon != std::string::npos && colon < end && colon - start == name.size()) {
      bool same = true;
      for (size_t i = 0; i < name.size() && same; ++i) {
        same = std::tolower(static_cast<unsigned char>(request[start + i])) == name[i];
      }
      if (same) {
        size_t b = colon + 1, e = end;
        while (b < e && (request[b] == ' ' || request[b] == '\t')) ++b;
        while (e > b && (request[e - 1] == ' ' || request[e - 1] == '\t')) --e;
        values.push_back(request.substr(b, e - b));
      }
    }
    pos = end;
  }
  return values;
}

// The value of header `name` (lower case), its first; "" when absent.
std::string header_value(const std::string& request, const std::string& name) {
  std::vector<std::string> values = header_values(request, name, 1);
  return values.empty() ? std::string() : std::move(values[0]);
}

// A handler that throws (out of memory) answers 500 instead of ending the process from a worker thread.
template <class H>
HttpResponse call_handler(const H& handler, const HttpRequest& request) {
  try {
    return handler.handler(request);
  } catch (const std::exception& e) {
    return HttpResponse::error(500, std::string("internal error: ") + e.what());
  }
}

bool is_regular_file(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

}  // namespace

HttpResponse HttpResponse::error(int status, std::string reason) {
  HttpResponse r;
  r.status = status;
  r.content_type = "text/plain; charset=utf-8";
  for (char& c : reason)
    if (c == '\n' || c == '\r') c = ' ';
  r.body = std::move(reason) + "\n";
  return r;
}

bool query_value(const std::string& query, const std::string& name, std::string& value) {
  size_t start = 0;
  while (start <= query.size()) {
    const size_t end = std::min(query.find('&', start), query.size());
    const size_t eq = query.find('=', start);
    if (eq != std::string::npos && eq < end && query.compare(start, eq - start, name) == 0) {
      value.clear();
      for (size_t i = eq + 1; i < end; ++i) {
        if (query[i] == '%') {
          if (i + 2 >= end) return false;
          const int hi = hex_value(query[i + 1]), lo = hex_value(query[i + 2]);
          if (hi < 0 || lo < 0) return false;
          value += static_cast<char>(hi * 16 + lo);
          i += 2;
        } else {
          value += query[i] == '+' ? ' ' : query[i];
        }
      }
      return true;
    }
    start = end + 1;
  }
  return false;
}

void StaticServer::add_handler(std::string method, std::string url_path, HttpHandler handler) {
  handlers_.push_back({std::move(method), std::move(url_path), std::move(handler)});
}

StaticServer::~StaticServer() {
  if (listen_fd_ >= 0) ::close(listen_fd_);
}

std::string StaticServer::content_type_for(const std::string& path) {
  const size_t dot = path.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot + 1);
  if (ext == "html") return "text/html; charset=utf-8";
  if (ext == "js" || ext == "mjs") return "text/javascript; charset=utf-8";
  if (ext == "json") return "application/json";
  if (ext == "css") return "text/css; charset=utf-8";
  if (ext == "glb") return "model/gltf-binary";
  if (ext == "gltf") return "model/gltf+json";
  if (ext == "png") return "image/png";
  if (ext == "jpg" || ext == "jpeg") return "image/jpeg";
  if (ext == "wasm") return "application/wasm";
  if (ext == "svg") return "image/svg+xml";
  return "application/octet-stream";
}

std::string StaticServer::safe_request_path(const std::string& target) {
  std::string raw = target.substr(0, target.find_first_of("?#"));
  if (raw.empty() || raw[0] != '/') return {};
  std::string path;
  for (size_t i = 0; i < raw.size(); ++i) {
    if (raw[i] == '%') {
      if (i + 2 >= raw.size()) return {};
      const int hi = hex_value(raw[i + 1]), lo = hex_value(raw[i + 2]);
      if (hi < 0 || lo < 0) return {};
      path += static_cast<char>(hi * 16 + lo);
      i += 2;
    } else {
      path += raw[i];
    }
  }
  if (path.find('\0') != std::string::npos || path.find('\\') != std::string::npos) return {};
  // Refuse any ".." segment (also "/a/../b": nothing legitimate needs it).
  size_t start = 0;
  while (start <= path.size()) {
    const size_t end = std::min(path.find('/', start), path.size());
    if (path.compare(start, end - start, "..") == 0) return {};
    start = end + 1;
  }
  return path;
}

Status StaticServer::start(const std::string& web_root, std::vector<Route> routes, int port) {
  if (port < 0 || port > 65535) {
    return Status::error(ErrorCode::kInvalidArgument, "", "port must be 0..65535", std::to_string(port));
  }
  std::array<char, PATH_MAX> real{};
  struct stat st {};
  if (::realpath(web_root.c_str(), real.data()) == nullptr || ::stat(real.data(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    return Status::error(ErrorCode::kInvalidArgument, web_root, "web root is not a directory");
  }
  root_ = real.data();
  while (root_.size() > 1 && root_.back() == '/') root_.pop_back();
  routes_ = std::move(routes);

  listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0)
    return Status::error(ErrorCode::kIo, "", std::string("cannot open a socket: ") + std::strerror(errno));
  const int yes = 1;
  ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);  // never reachable from other machines
  addr.sin_port = htons(static_cast<uint16_t>(port));
  if (::bind(listen_fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    const int err = errno;
    ::close(listen_fd_);
    listen_fd_ = -1;
    return Status::error(ErrorCode::kIo, "", "cannot listen on 127.0.0.1:" + std::to_string(port), std::strerror(err));
  }
  if (::listen(listen_fd_, SOMAXCONN) != 0) {
    ::close(listen_fd_);
    listen_fd_ = -1;
    return Status::error(ErrorCode::kIo, "", std::string("cannot listen: ") + std::strerror(errno));
  }
  socklen_t len = sizeof addr;
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
  return Status::ok();
}

void StaticServer::serve(const std::atomic<bool>& stop) {
  // One thread per connection; finished ones are joined as soon as they are done, so one slow
  // client never holds up the others or the accept loop.
  struct Worker {
    std::thread thread;
    std::atomic<bool> done{false};
    Connection conn;
  };
  std::list<Worker> workers;
  auto reap = [&workers](bool all) {
    for (auto it = workers.begin(); it != workers.end();) {
      if (!all && !it->done.load()) {
        ++it;
        continue;
      }
      it->thread.join();
      it = workers.erase(it);
    }
  };
  while (!stop.load()) {
    reap(false);
    pollfd pfd{listen_fd_, POLLIN, 0};
    const int ready = ::poll(&pfd, 1, kPollMillis);
    if (ready <= 0) continue;  // timeout, or EINTR from Ctrl-C: look at the flag again
    const int client = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (client < 0) continue;
    // Full: drop the oldest connection that has not sent its request yet (idle or trickling
    // sockets cannot lock real requests out); its worker sees the shutdown at once and ends.
    size_t busy = 0;
    for (Worker& w : workers) busy += w.done.load() || w.conn.dropped() ? 0 : 1;
    if (busy >= kMaxWorkers) {
      bool dropped = false;
      for (Worker& w : workers) {
        if (!w.done.load() && w.conn.drop_if_waiting()) {
          dropped = true;
          break;
        }
      }
      if (!dropped) {
        send_status(client, 503, "Service Unavailable", stop);
        ::close(client);
        continue;
      }
    }
    Worker& w = workers.emplace_back();
    w.conn.fd = client;
    w.thread = std::thread([this, &stop, &w] {
      handle(w.conn, stop);
      w.conn.close();
      w.done.store(true);
    });
  }
  reap(true);  // workers see the flag within kPollMillis
}

std::string StaticServer::resolve_under_root(const std::string& path) const {
  std::string candidate = root_ + (path == "/" ? std::string("/index.html") : path);
  if (!candidate.empty() && candidate.back() == '/') candidate += "index.html";
  std::array<char, PATH_MAX> real{};
  if (::realpath(candidate.c_str(), real.data()) == nullptr) return {};
  const std::string resolved = real.data();
  // The resolved file must stay inside the root even through symlinks.
  if (resolved.compare(0, root_.size() + 1, root_ + "/") != 0) return {};
  return is_regular_file(resolved) ? resolved : std::string();
}

bool StaticServer::Connection::drop_if_waiting() {
  const std::lock_guard<std::mutex> lock(mutex);
  if (state != State::kWaiting) return false;
  state = State::kDropped;
  ::shutdown(fd, SHUT_RDWR);
  return true;
}

bool StaticServer::Connection::start_serving() {
  const std::lock_guard<std::mutex> lock(mutex);
  if (state != State::kWaiting) return false;
  state = State::kServing;
  return true;
}

bool StaticServer::Connection::dropped() {
  const std::lock_guard<std::mutex> lock(mutex);
  return state == State::kDropped;
}

void StaticServer::Connection::close() {
  const std::lock_guard<std::mutex> lock(mutex);
  state = State::kClosed;
  ::close(fd);
}

bool StaticServer::host_allowed(const std::string& host) const {
  std::string port = std::to_string(port_);
  port.insert(port.begin(), ':');
  std::string lower = host;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (lower.size() <= port.size() || lower.compare(lower.size() - port.size(), port.size(), port) != 0) return false;
  const std::string_view name = std::string_view(lower).substr(0, lower.size() - port.size());
  return name == "127.0.0.1" || name == "localhost" || name == "[::1]";
}

bool StaticServer::origin_allowed(const std::string& origin) const {
  if (origin.empty()) return true;  // curl and scripts send none; browsers send it on every POST
  const std::string scheme = "http://";
  if (origin.compare(0, scheme.size(), scheme) != 0) return false;
  return host_allowed(origin.substr(scheme.size()));
}

void StaticServer::answer(int client, const HttpResponse& response, bool head_only,
                          const std::atomic<bool>& stop) const {
  const std::string head = header_for(response.body.size(), response.content_type, response.status, response.headers);
  if (send_all(client, head.data(), head.size(), stop) && !head_only)
    send_all(client, response.body.data(), response.body.size(), stop);
}

void StaticServer::handle(Connection& conn, const std::atomic<bool>& stop) const {
  const int client = conn.fd;
  std::string request;
  std::array<char, 4096> buf{};
  const auto deadline = Clock::now() + std::chrono::seconds(kHeaderSeconds);
  while (request.find("\r\n\r\n") == std::string::npos) {
    if (request.size() > kMaxHeaderBytes) return send_status(client, 431, "Request Header Fields Too Large", stop);
    if (!wait_ready(client, POLLIN, stop, deadline)) return;
    const ssize_t n = ::recv(client, buf.data(), buf.size(), MSG_DONTWAIT);
    if (n < 0 && (errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK)) continue;
    if (n <= 0) return;
    request.append(buf.data(), static_cast<size_t>(n));
  }
  const size_t line_end = request.find("\r\n");
  const std::string line = request.substr(0, line_end);
  const size_t sp1 = line.find(' ');
  const size_t sp2 = sp1 == std::string::npos ? std::string::npos : line.find(' ', sp1 + 1);
  if (sp2 == std::string::npos) return send_status(client, 400, "Bad Request", stop);
  // DNS rebinding: a page from another site whose name now resolves to 127.0.0.1 sends its own
  // name as Host. Only the loopback names with this port are answered.
  if (!host_allowed(header_value(request, "host"))) return send_status(client, 403, "Forbidden", stop);
  const std::string method = line.substr(0, sp1);
  // A POST stays droppable until its body has arrived too: 64 slow bodies would otherwise lock
  // real requests out for their whole body deadline, as slow headers cannot.
  if (method != "POST" && !conn.start_serving()) return;  // dropped for a newer connection just now
  const std::string target = line.substr(sp1 + 1, sp2 - sp1 - 1);
  if (method != "GET" && method != "HEAD" && method != "POST")
    return send_status(client, 405, "Method Not Allowed", stop);
  const bool head_only = method == "HEAD";
  const std::string path = safe_request_path(target);
  if (path.empty()) return send_status(client, 403, "Forbidden", stop);

  const Handler* handler = nullptr;
  for (const Handler& h : handlers_) {
    if (h.url_path == path && (h.method == method || (h.method == "GET" && head_only))) handler = &h;
  }
  if (method == "POST") {
    if (handler == nullptr) return send_status(client, 405, "Method Not Allowed", stop);
    if (!origin_allowed(header_value(request, "origin"))) return send_status(client, 403, "Forbidden", stop);
    const std::string type = header_value(request, "content-type");
    if (type.compare(0, 16, "application/json") != 0)
      return answer(client, HttpResponse::error(415, "POST needs Content-Type: application/json"), false, stop);
    // Two lengths (even equal ones) leave the body's end open to how each reader picks: refused
    // (RFC 9112, 6.3), as a request smuggled past a proxy would carry them.
    const std::vector<std::string> lengths = header_values(request, "content-length", 2);
    if (lengths.size() > 1)
      return answer(client, HttpResponse::error(400, "more than one Content-Length"), false, stop);
    const std::string length_text = lengths.empty() ? std::string() : lengths[0];
    uint64_t length = 0;
    const auto [end, error] = std::from_chars(length_text.data(), length_text.data() + length_text.size(), length);
    // No Content-Length and no Transfer-Encoding: no body (RFC 9112; `curl -X POST` sends neither).
    // Chunked bodies are refused: the length must be known before anything is read.
    // A length past 2^64 is a body over the limit, not a missing length.
    if (error == std::errc::result_out_of_range && end == length_text.data() + length_text.size())
      return answer(client, HttpResponse::error(413, "body over 16 MiB"), false, stop);
    if ((!length_text.empty() && (error != std::errc() || end != length_text.data() + length_text.size())) ||
        !header_value(request, "transfer-encoding").empty())
      return answer(client, HttpResponse::error(411, "POST needs a Content-Length"), false, stop);
    if (length > kMaxBodyBytes) return answer(client, HttpResponse::error(413, "body over 16 MiB"), false, stop);
    HttpRequest req{method, path, {}, request.substr(request.find("\r\n\r\n") + 4)};
    const auto body_deadline = Clock::now() + std::chrono::seconds(kBodySeconds);
    while (req.body.size() < length) {
      if (!wait_ready(client, POLLIN, stop, body_deadline)) return;
      const ssize_t n = ::recv(client, buf.data(), std::min(buf.size(), length - req.body.size()), MSG_DONTWAIT);
      if (n < 0 && (errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK)) continue;
      if (n <= 0) return;
      req.body.append(buf.data(), static_cast<size_t>(n));
    }
    if (req.body.size() > length) req.body.resize(length);
    if (!conn.start_serving()) return;  // dropped for a newer connection while its body came
    return answer(client, call_handler(*handler, req), false, stop);
  }
  if (handler != nullptr) {
    const size_t q = target.find('?');
    const HttpRequest req{method, path, q == std::string::npos ? std::string() : target.substr(q + 1), {}};
    return answer(client, call_handler(*handler, req), head_only, stop);
  }

  std::string file;
  for (const Route& r : routes_) {
    if (r.url_path != path) continue;
    const std::string type = r.content_type.empty() ? content_type_for(path) : r.content_type;
    if (r.file.empty()) {
      const std::string head = header_for(r.content.size(), type);
      if (send_all(client, head.data(), head.size(), stop) && !head_only)
        send_all(client, r.content.data(), r.content.size(), stop);
      return;
    }
    file = r.file;
    break;
  }
  if (file.empty()) file = resolve_under_root(path);
  if (file.empty()) return send_status(client, 404, "Not Found", stop);

  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) return send_status(client, 404, "Not Found", stop);
  const auto size = static_cast<size_t>(in.tellg());
  in.seekg(0);
  const std::string head = header_for(size, content_type_for(file));
  if (!send_all(client, head.data(), head.size(), stop) || head_only) return;
  std::vector<char> chunk(1 << 16);
  size_t left = size;
  while (left > 0 && in) {
    const size_t n = std::min(left, chunk.size());
    in.read(chunk.data(), static_cast<std::streamsize>(n));
    if (!send_all(client, chunk.data(), static_cast<size_t>(in.gcount()), stop)) return;
    left -= static_cast<size_t>(in.gcount());
  }
}

}  // namespace tailor::cli
