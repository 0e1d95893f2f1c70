// The static file server behind `tailor view` (see http_server.h).
#include "http_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <thread>

namespace tailor::cli {
namespace {

constexpr size_t kMaxHeaderBytes = 16 * 1024;  // a GET from a browser is well under 2 KB
constexpr int kPollMillis = 200;               // how often serve() looks at the stop flag
constexpr int kClientTimeoutSeconds = 10;      // a silent client (speculative connection) is dropped

bool send_all(int fd, const char* data, size_t size) {
  while (size > 0) {
    const ssize_t n = ::send(fd, data, size, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data += n;
    size -= static_cast<size_t>(n);
  }
  return true;
}

void send_status(int fd, int code, const char* reason) {
  const std::string body = std::to_string(code) + " " + reason + "\n";
  const std::string head = "HTTP/1.1 " + std::to_string(code) + " " + reason +
                           "\r\nContent-Type: text/plain\r\nContent-Length: " + std::to_string(body.size()) +
                           "\r\nConnection: close\r\n\r\n";
  send_all(fd, head.data(), head.size());
  send_all(fd, body.data(), body.size());
}

std::string header_for(size_t length, const std::string& type) {
  return "HTTP/1.1 200 OK\r\nContent-Type: " + type + "\r\nContent-Length: " + std::to_string(length) +
         "\r\nCache-Control: no-cache\r\nX-Content-Type-Options: nosniff\r\nConnection: close\r\n\r\n";
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool is_regular_file(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

}  // namespace

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
  if (listen_fd_ < 0) return Status::error(ErrorCode::kIo, "", std::string("cannot open a socket: ") + std::strerror(errno));
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
  if (::listen(listen_fd_, 64) != 0) {
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
  std::vector<std::thread> workers;
  while (!stop.load()) {
    pollfd pfd{listen_fd_, POLLIN, 0};
    const int ready = ::poll(&pfd, 1, kPollMillis);
    if (ready <= 0) continue;  // timeout, or EINTR from Ctrl-C: look at the flag again
    const int client = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (client < 0) continue;
    timeval tv{kClientTimeoutSeconds, 0};
    ::setsockopt(client, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    ::setsockopt(client, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
    workers.emplace_back([this, client] {
      handle(client);
      ::close(client);
    });
    // Reap finished workers now and then so a long session does not pile up threads.
    if (workers.size() > 64) {
      for (auto& w : workers) w.join();
      workers.clear();
    }
  }
  for (auto& w : workers) w.join();
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

void StaticServer::handle(int client) const {
  std::string request;
  std::array<char, 4096> buf{};
  while (request.find("\r\n\r\n") == std::string::npos) {
    if (request.size() > kMaxHeaderBytes) return send_status(client, 431, "Request Header Fields Too Large");
    const ssize_t n = ::recv(client, buf.data(), buf.size(), 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    request.append(buf.data(), static_cast<size_t>(n));
  }
  const size_t line_end = request.find("\r\n");
  const std::string line = request.substr(0, line_end);
  const size_t sp1 = line.find(' ');
  const size_t sp2 = sp1 == std::string::npos ? std::string::npos : line.find(' ', sp1 + 1);
  if (sp2 == std::string::npos) return send_status(client, 400, "Bad Request");
  const std::string method = line.substr(0, sp1);
  const std::string target = line.substr(sp1 + 1, sp2 - sp1 - 1);
  if (method != "GET" && method != "HEAD") return send_status(client, 405, "Method Not Allowed");
  const bool head_only = method == "HEAD";
  const std::string path = safe_request_path(target);
  if (path.empty()) return send_status(client, 403, "Forbidden");

  std::string file;
  for (const Route& r : routes_) {
    if (r.url_path != path) continue;
    const std::string type = r.content_type.empty() ? content_type_for(path) : r.content_type;
    if (r.file.empty()) {
      const std::string head = header_for(r.content.size(), type);
      if (send_all(client, head.data(), head.size()) && !head_only) send_all(client, r.content.data(), r.content.size());
      return;
    }
    file = r.file;
    break;
  }
  if (file.empty()) file = resolve_under_root(path);
  if (file.empty()) return send_status(client, 404, "Not Found");

  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) return send_status(client, 404, "Not Found");
  const auto size = static_cast<size_t>(in.tellg());
  in.seekg(0);
  const std::string head = header_for(size, content_type_for(file));
  if (!send_all(client, head.data(), head.size()) || head_only) return;
  std::vector<char> chunk(1 << 16);
  size_t left = size;
  while (left > 0 && in) {
    const size_t n = std::min(left, chunk.size());
    in.read(chunk.data(), static_cast<std::streamsize>(n));
    if (!send_all(client, chunk.data(), static_cast<size_t>(in.gcount()))) return;
    left -= static_cast<size_t>(in.gcount());
  }
}

}  // namespace tailor::cli
