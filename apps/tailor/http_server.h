// A minimal file server for `tailor view` and `tailor edit`: HTTP/1.1 GET (and HEAD), and POST to
// handlers, bound to 127.0.0.1 only, one short-lived connection per request (Connection: close).
//
// What it serves, in this order:
//   1. handlers (add_handler): a method and an URL path answered by a callback (tailor edit's API);
//   2. explicit routes: an URL path mapped to one file on disk, or to bytes held in memory
//      (the model, its textures, the generated /config.json);
//   3. files under the web root (index.html for "/"), after refusing any path with a ".."
//      segment, a backslash or a NUL byte, and checking that the resolved real path (symlinks
//      followed) still lies inside the root.
// Everything else gets 404; other methods, and POST to a path without a handler, get 405. A POST
// body must come with a Content-Length (411 for chunked ones; at most 16 MiB, 413; none: no body)
// and every POST with Content-Type: application/json
// (415), and an Origin header, when sent, must be this server's: a page from another site cannot
// send such a request without a CORS preflight, which is refused (cross-site request forgery).
// Not meant for untrusted networks: it listens on the loopback interface only.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "tailor/status.h"

namespace tailor::cli {

//! One explicit route. Exactly one of file / content is used: file when not empty.
struct Route {
  std::string url_path;      //!< e.g. "/files/model.glb" (decoded, leading '/')
  std::string file;          //!< file on disk to send
  std::string content;       //!< bytes to send when file is empty
  std::string content_type;  //!< empty: from the extension of url_path
};

//! A request as a handler sees it.
struct HttpRequest {
  std::string method;  //!< "GET", "HEAD" or "POST"
  std::string path;    //!< decoded, as safe_request_path gives it
  std::string query;   //!< the raw text after '?', without it ("" when none)
  std::string body;    //!< POST: the body (Content-Length bytes)
};

//! A handler's answer. Status codes other than 200 carry a one-line reason as text/plain body.
struct HttpResponse {
  int status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::vector<std::pair<std::string, std::string>> headers;  //!< extra headers (name, value)

  //! An error answer: `status` with `reason` (one line) as its text body.
  static HttpResponse error(int status, std::string reason);
};

using HttpHandler = std::function<HttpResponse(const HttpRequest&)>;

//! Value of `name` in a query string ("version=3&x=1"), %-decoded; false when absent or malformed.
bool query_value(const std::string& query, const std::string& name, std::string& value);

class StaticServer {
 public:
  StaticServer() = default;
  StaticServer(const StaticServer&) = delete;
  StaticServer& operator=(const StaticServer&) = delete;
  ~StaticServer();

  //! Binds 127.0.0.1:port (port 0: a free port chosen by the system) and listens.
  //! Fails with kIo when the port is taken or sockets are unavailable, kInvalidArgument for a
  //! port outside 0..65535 or a web root that is not a directory.
  Status start(const std::string& web_root, std::vector<Route> routes, int port);

  //! Answers `method` ("GET" or "POST"; GET handlers also answer HEAD) requests for `url_path` by
  //! `handler`, called on the connection's thread (handlers run concurrently). Before serve().
  void add_handler(std::string method, std::string url_path, HttpHandler handler);

  //! The port actually bound (after start).
  int port() const { return port_; }

  //! Answers requests until `stop` becomes true (checked at least every 200 ms), e.g. set from
  //! a SIGINT handler. Each connection is served on its own thread, joined as soon as it ends; at
  //! most 64 at once: when full, a new connection replaces the oldest one that has not sent its
  //! request yet, and gets 503 only when all 64 are being answered. A client must send its request
  //! within 2 s and take each part of the answer within 30 s. Requests whose Host is not
  //! 127.0.0.1:PORT, localhost:PORT or [::1]:PORT get 403 (DNS rebinding). Every answer carries a
  //! Content-Security-Policy limiting the page to this server's files. Workers also watch `stop`,
  //! so the return is prompt.
  void serve(const std::atomic<bool>& stop);

  //! Content type for a path from its extension ("application/octet-stream" when unknown).
  static std::string content_type_for(const std::string& path);

  //! The decoded path of a request target ("/a%20b.png?x=1" -> "/a b.png"), or "" when it is
  //! malformed or unsafe (".." segment, backslash, NUL, bad %-escape, not starting with '/').
  static std::string safe_request_path(const std::string& target);

 private:
  //! One accepted socket, shared by its worker and the accept loop (which may drop it while it
  //! waits for its request). The mutex orders the drop against the worker's start and close.
  struct Connection {
    enum class State : uint8_t { kWaiting, kServing, kDropped, kClosed };
    int fd = -1;
    std::mutex mutex;
    State state = State::kWaiting;
    bool drop_if_waiting();  //!< shuts the socket down when still kWaiting; true when it did
    bool start_serving();    //!< kWaiting -> kServing; false when dropped
    bool dropped();
    void close();
  };

  struct Handler {
    std::string method;
    std::string url_path;
    HttpHandler handler;
  };

  bool host_allowed(const std::string& host) const;
  bool origin_allowed(const std::string& origin) const;
  void answer(int client, const HttpResponse& response, bool head_only, const std::atomic<bool>& stop) const;
  void handle(Connection& conn, const std::atomic<bool>& stop) const;
  std::string resolve_under_root(const std::string& path) const;

  int listen_fd_ = -1;
  int port_ = 0;
  std::string root_;  // real path of the web root, no trailing '/'
  std::vector<Route> routes_;
  std::vector<Handler> handlers_;
};

}  // namespace tailor::cli
