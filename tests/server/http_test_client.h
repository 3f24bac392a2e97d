// A minimal HTTP/1.1 client over raw sockets for the web-page tests: one connection per request
// ("Connection: close", read to the end), an optional local address (127.0.0.x: another client
// as the server counts clients), bounded by a deadline; and the raw socket for abuse tests
// (slow or oversized requests). Header-only.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <map>
#include <optional>
#include <regex>
#include <string>

namespace driftlab::testing {

struct HttpResponse {
  int status = 0;  // 0: no response (connection closed or timed out first)
  std::multimap<std::string, std::string> headers;  // names in lower case
  std::string body;

  std::string Header(const std::string& name) const {
    const auto it = headers.find(name);
    return it == headers.end() ? "" : it->second;
  }
};

// A connected TCP socket to 127.0.0.1:port from `local_ip` (any port); -1 on failure.
inline int ConnectHttp(int port, const std::string& local_ip = "127.0.0.1") {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  sockaddr_in local{};
  local.sin_family = AF_INET;
  inet_pton(AF_INET, local_ip.c_str(), &local.sin_addr);
  sockaddr_in remote{};
  remote.sin_family = AF_INET;
  remote.sin_port = htons(static_cast<uint16_t>(port));
  inet_pton(AF_INET, "127.0.0.1", &remote.sin_addr);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&local), sizeof(local)) != 0 ||
      ::connect(fd, reinterpret_cast<sockaddr*>(&remote), sizeof(remote)) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// Sends all of `data` (false when the peer closed or the deadline passed).
inline bool SendAll(int fd, const std::string& data,
                    std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  size_t done = 0;
  while (done < data.size()) {
    pollfd p{fd, POLLOUT, 0};
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0 || ::poll(&p, 1, static_cast<int>(left.count())) <= 0) return false;
    const ssize_t n = ::send(fd, data.data() + done, data.size() - done, MSG_NOSIGNAL);
    if (n <= 0) return false;
    done += static_cast<size_t>(n);
  }
  return true;
}

// Reads until the peer closes or the deadline passes; true when the peer closed.
inline bool ReadToClose(int fd, std::string* out,
                        std::chrono::milliseconds timeout = std::chrono::seconds(10)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  char buffer[16384];
  for (;;) {
    pollfd p{fd, POLLIN, 0};
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0 || ::poll(&p, 1, static_cast<int>(left.count())) <= 0) return false;
    const ssize_t n = ::recv(fd, buffer, sizeof(buffer), 0);
    if (n <= 0) return true;
    out->append(buffer, static_cast<size_t>(n));
  }
}

inline HttpResponse ParseHttpResponse(const std::string& raw) {
  HttpResponse response;
  const size_t head_end = raw.find("\r\n\r\n");
  if (raw.rfind("HTTP/1.", 0) != 0 || head_end == std::string::npos) return response;
  response.status = std::atoi(raw.substr(9, 3).c_str());
  size_t at = raw.find("\r\n") + 2;
  while (at < head_end) {
    const size_t end = raw.find("\r\n", at);
    const std::string line = raw.substr(at, end - at);
    const size_t colon = line.find(':');
    if (colon != std::string::npos) {
      std::string name = line.substr(0, colon);
      for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      size_t value = colon + 1;
      while (value < line.size() && line[value] == ' ') ++value;
      response.headers.emplace(name, line.substr(value));
    }
    at = end + 2;
  }
  response.body = raw.substr(head_end + 4);
  return response;
}

// One request on a new connection; `head` holds extra header lines ("Name: value\r\n").
inline HttpResponse HttpRequest(int port, const std::string& method, const std::string& path,
                                const std::string& head = "", const std::string& body = "",
                                const std::string& local_ip = "127.0.0.1") {
  const int fd = ConnectHttp(port, local_ip);
  if (fd < 0) return {};
  std::string request = method + " " + path +
                        " HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
                        "\r\nConnection: close\r\n" + head;
  if (method == "POST") {
    request += "Content-Type: application/x-www-form-urlencoded\r\nContent-Length: " +
               std::to_string(body.size()) + "\r\n";
  }
  request += "\r\n" + body;
  std::string raw;
  if (SendAll(fd, request)) ReadToClose(fd, &raw);
  ::close(fd);
  return ParseHttpResponse(raw);
}

// A signed-in browser: its session cookie and the form token of its pages.
struct WebSession {
  std::string cookie;  // "driftlab_session=..."
  std::string csrf;
  std::string Head() const { return "Cookie: " + cookie + "\r\n"; }
};

// Signs in with `token` from `local_ip`; the session is empty when sign-in failed.
inline WebSession SignIn(int port, const std::string& token,
                         const std::string& local_ip = "127.0.0.1") {
  WebSession session;
  const HttpResponse signin = HttpRequest(port, "POST", "/signin", "", "token=" + token, local_ip);
  const std::string set_cookie = signin.Header("set-cookie");
  if (signin.status != 303 || set_cookie.empty()) return session;
  session.cookie = set_cookie.substr(0, set_cookie.find(';'));
  const HttpResponse page = HttpRequest(port, "GET", "/jobs", session.Head(), "", local_ip);
  std::smatch match;
  static const std::regex kCsrf("name=\"csrf\" value=\"([0-9a-f]{64})\"");
  if (std::regex_search(page.body, match, kCsrf)) session.csrf = match[1];
  return session;
}

}  // namespace driftlab::testing
