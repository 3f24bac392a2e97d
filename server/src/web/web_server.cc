// Routes of the web pages (web_server.h): sign-in, sessions, CSRF, security headers, and the owner
// checks, which go through the JobManager (jobs) and the owner column of the store (calibrations)
// exactly as the gRPC services do.
//
// Routing is by exact path segments here, before httplib's regular-expression router: GET and
// HEAD of every page are answered in the pre-routing handler; only the three POST forms reach
// httplib's router, with fixed patterns, after their path has been checked.
#include "driftlab/server/web_server.h"

#include <fmt/format.h>
#include <openssl/evp.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <map>
#include <thread>

#include "driftlab/app/result_file.h"
#include "driftlab/report/html_report.h"
#include "driftlab/server/data_services.h"
#include "driftlab/spec_error.h"
#include "web/bounded_http_server.h"
#include "web/pages.h"
#include "web/sessions.h"

namespace driftlab::server::web::embedded {
extern const char kAppCss[];
extern const char kAppJs[];
}  // namespace driftlab::server::web::embedded

namespace driftlab::server {
namespace {

using web::Session;
using web::Viewer;

constexpr const char* kAppCsp =
    "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self'; "
    "connect-src 'self'; form-action 'self'; frame-ancestors 'none'; base-uri 'none'";
constexpr size_t kMaxFormBytes = 16 << 10;
constexpr size_t kMaxNameFilterBytes = 256;
constexpr uint32_t kListPageSize = 100;

bool IsJobId(std::string_view id) {
  if (id.size() != 28 || id.substr(0, 4) != "job-") return false;
  return std::all_of(id.begin() + 4, id.end(),
                     [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

bool IsCalibrationId(std::string_view id) {
  if (id.size() != 28 || id.substr(0, 4) != "cal-") return false;
  return std::all_of(id.begin() + 4, id.end(),
                     [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

std::vector<std::string> Segments(const std::string& path) {
  std::vector<std::string> segments;
  size_t at = 1;
  while (at <= path.size()) {
    const size_t end = std::min(path.find('/', at), path.size());
    segments.push_back(path.substr(at, end - at));
    at = end + 1;
  }
  return segments;
}

// Base64 of the SHA-256 of `text`, for a CSP 'sha256-...' source.
std::string Sha256Base64(std::string_view text) {
  unsigned char digest[32];
  unsigned int length = 0;
  EVP_Digest(text.data(), text.size(), digest, &length, EVP_sha256(), nullptr);
  unsigned char encoded[48];
  const int n = EVP_EncodeBlock(encoded, digest, 32);
  return std::string(reinterpret_cast<char*>(encoded), static_cast<size_t>(n));
}

// The policy of a served report: only the report's own inline scripts (by hash), inline styles,
// data: images; sandboxed, so its scripts run in an opaque origin without the session's cookie.
std::string ReportCsp(const std::string& html) {
  std::string scripts;
  for (size_t at = html.find("<script>"); at != std::string::npos; at = html.find("<script>", at)) {
    const size_t begin = at + 8;
    const size_t end = html.find("</script>", begin);
    if (end == std::string::npos) break;
    scripts += " 'sha256-" + Sha256Base64(std::string_view(html).substr(begin, end - begin)) + "'";
    at = end;
  }
  return "default-src 'none'; script-src" + (scripts.empty() ? std::string(" 'none'") : scripts) +
         "; style-src 'unsafe-inline'; img-src data: blob:; frame-ancestors 'none'; "
         "form-action 'none'; base-uri 'none'; sandbox allow-scripts allow-downloads";
}

std::map<std::string, std::string> ParseForm(const std::string& body) {
  httplib::Params params;
  httplib::detail::parse_query_text(body, params);
  std::map<std::string, std::string> form;
  for (const auto& [key, value] : params) form.emplace(key, value);
  return form;
}

}  // namespace

class WebServer::Impl {
 public:
  Impl(const WebOptions& options, const WebContext& context)
      : options_(options),
        context_(context),
        sessions_(options.session_idle, options.session_lifetime, 10000),
        throttle_(options.sign_in_burst, options.sign_in_refill, 10000) {
    if (options.tls_cert.has_value() != options.tls_key.has_value()) {
      throw SpecError("--tls-cert", "", "--tls-cert and --tls-key together");
    }
    if (options.tls_cert)
      tls_ = std::make_unique<web::TlsContext>(*options.tls_cert, *options.tls_key);
    secure_ = tls_ != nullptr;
    cookie_name_ = secure_ ? "__Host-driftlab_session" : "driftlab_session";
    web::ConnectionLimits limits;
    limits.threads = options.threads;
    limits.queue = options.queue;
    limits.per_client = options.max_connections_per_client;
    limits.request_timeout = options.request_timeout;
    limits.write_timeout = options.write_timeout;
    limits.keep_alive_timeout = options.keep_alive_timeout;
    http_ = std::make_unique<web::BoundedHttpServer>(limits, tls_.get(),
                                                     [this](httplib::Request& req) { Setup(req); });
    http_->set_payload_max_length(kMaxFormBytes);
    http_->set_keep_alive_max_count(limits.max_requests_per_connection);
    http_->set_keep_alive_timeout(
        std::max<time_t>(1, static_cast<time_t>(options.keep_alive_timeout.count() / 1000)));
    http_->set_pre_routing_handler(
        [this](const httplib::Request& req, httplib::Response& res) { return Route(req, res); });
    http_->Post("/signin",
                [this](const httplib::Request& req, httplib::Response& res) { SignIn(req, res); });
    http_->Post("/signout",
                [this](const httplib::Request& req, httplib::Response& res) { SignOut(req, res); });
    http_->Post(R"(/jobs/(job-[0-9a-f]{24})/cancel)",
                [this](const httplib::Request& req, httplib::Response& res) {
                  Cancel(req, res, req.matches[1]);
                });
    http_->set_post_routing_handler(
        [](const httplib::Request&, httplib::Response& res) { SecurityHeaders(res); });
    http_->set_exception_handler(
        [](const httplib::Request&, httplib::Response& res, std::exception_ptr error) {
          std::string what = "unknown";
          try {
            std::rethrow_exception(error);
          } catch (const std::exception& e) {
            what = e.what();
          } catch (...) {
          }
          spdlog::error("web: internal error: {}", MessageText(what, kMaxMessageTextBytes));
          res.status = 500;
          res.set_content("internal error\n", "text/plain; charset=utf-8");
        });
    const int port = options.port == 0
                         ? http_->bind_to_any_port(options.host)
                         : (http_->bind_to_port(options.host, options.port) ? options.port : -1);
    if (port <= 0) {
      throw SpecError("--http-port", options.host + ":" + std::to_string(options.port),
                      "an address and port this host can listen on");
    }
    if (!http_->WidenBacklog()) {
      spdlog::warn("web: the listening socket keeps its backlog of 5: {}", std::strerror(errno));
    }
    port_ = port;
    thread_ = std::thread([this] { http_->listen_after_bind(); });
    // Stop() before the accept loop runs would find nothing to stop: wait (bounded) for it.
    for (int i = 0; i < 5000 && !http_->is_running(); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    if (!context_.auth->enabled()) {
      spdlog::warn("web: no --tokens file: every visitor is owner \"{}\"", kAnonymousOwner);
    }
    spdlog::info("web pages on {}://{}:{}", secure_ ? "https" : "http", options.host, port_);
  }

  ~Impl() { Stop(); }

  void Stop() {
    if (stopped_) return;
    stopped_ = true;
    http_->Stop();
    if (thread_.joinable()) thread_.join();
  }

  int port() const { return port_; }

 private:
  // ---------------------------------------------------------------- request plumbing

  // Before routing: no compression of pages that carry a form token next to reflected text
  // (BREACH), no byte ranges (multipart range responses multiply a response).
  static void Setup(httplib::Request& req) {
    const bool compressible = req.path.rfind("/static/", 0) == 0 ||
                              req.path.ends_with("/report.html") ||
                              req.path.ends_with("/result.json");
    if (!compressible) req.headers.erase("Accept-Encoding");
    req.headers.erase("Range");
    req.ranges.clear();
  }

  static void SecurityHeaders(httplib::Response& res) {
    if (!res.has_header("Content-Security-Policy")) {
      res.set_header("Content-Security-Policy", kAppCsp);
    }
    res.set_header("X-Content-Type-Options", "nosniff");
    res.set_header("X-Frame-Options", "DENY");
    res.set_header("Referrer-Policy", "same-origin");
    res.set_header("Cross-Origin-Opener-Policy", "same-origin");
    res.set_header("Cross-Origin-Resource-Policy", "same-origin");
    if (!res.has_header("Cache-Control")) res.set_header("Cache-Control", "no-store");
  }

  std::string CookieValue(const httplib::Request& req) const {
    const size_t count = req.get_header_value_count("Cookie");
    for (size_t i = 0; i < count; ++i) {
      const std::string header = req.get_header_value("Cookie", i);
      size_t at = 0;
      while (at < header.size()) {
        const size_t end = std::min(header.find(';', at), header.size());
        std::string_view pair(header.data() + at, end - at);
        while (!pair.empty() && pair.front() == ' ') pair.remove_prefix(1);
        const size_t eq = pair.find('=');
        if (eq != std::string_view::npos && pair.substr(0, eq) == cookie_name_) {
          return std::string(pair.substr(eq + 1));
        }
        at = end + 1;
      }
    }
    return "";
  }

  // The session of the request; without a tokens file every visitor gets one (owner anonymous).
  std::optional<Session> SessionOf(const httplib::Request& req, httplib::Response& res) {
    const std::string id = CookieValue(req);
    if (!id.empty()) {
      if (std::optional<Session> session = sessions_.Find(id)) return session;
    }
    if (context_.auth->enabled()) return std::nullopt;
    const std::string new_id = sessions_.Create(kAnonymousOwner);
    SetSessionCookie(res, new_id);
    return sessions_.Find(new_id);
  }

  void SetSessionCookie(httplib::Response& res, const std::string& id) const {
    res.set_header("Set-Cookie", cookie_name_ + "=" + id + "; Path=/; HttpOnly; SameSite=Lax" +
                                     (secure_ ? "; Secure" : ""));
  }

  static Viewer ViewerOf(const Session& session) { return Viewer{session.owner, session.csrf}; }

  static void Html(httplib::Response& res, int status, const std::string& html) {
    res.status = status;
    res.set_content(html, "text/html; charset=utf-8");
  }

  static void Redirect(httplib::Response& res, const std::string& location) {
    res.status = 303;
    res.set_header("Location", location);
  }

  static void NotFound(httplib::Response& res, const Viewer& viewer) {
    Html(res, 404, web::ErrorPage(viewer, 404, "Not found."));
  }

  void Download(httplib::Response& res, const std::string& body, const std::string& type,
                const std::string& filename) {
    res.status = 200;
    res.set_content(body, type);
    res.set_header("Content-Disposition", "attachment; filename=\"" + filename + "\"");
  }

  // A state-changing form: the session's CSRF token in the body, and no other site's origin.
  bool FormAllowed(const httplib::Request& req, const Session& session,
                   const std::map<std::string, std::string>& form) const {
    if (!SameOrigin(req)) return false;
    const auto it = form.find("csrf");
    return it != form.end() && web::SecretEquals(it->second, session.csrf);
  }

  bool SameOrigin(const httplib::Request& req) const {
    if (req.get_header_value("Sec-Fetch-Site") == "cross-site") return false;
    if (!req.has_header("Origin")) return true;
    const std::string expected =
        std::string(secure_ ? "https://" : "http://") + req.get_header_value("Host");
    return req.get_header_value("Origin") == expected;
  }

  // How the commands on the pages reach the gRPC port: the listen host, or for a wildcard listen
  // address the host the browser used (letters, digits, '.', '-', ':' and brackets only).
  web::GrpcTarget Grpc(const httplib::Request& req) const {
    std::string host = context_.grpc_listen.substr(0, context_.grpc_listen.rfind(':'));
    if (host.empty() || host == "0.0.0.0" || host == "[::]" || host == "::") {
      std::string browser = req.get_header_value("Host");
      if (!browser.empty() && browser.front() == '[') {
        browser = browser.substr(0, browser.find(']') + 1);
      } else {
        browser = browser.substr(0, browser.find(':'));
      }
      const bool clean = !browser.empty() && browser.size() < 256 &&
                         std::all_of(browser.begin(), browser.end(), [](char c) {
                           return std::isalnum(static_cast<unsigned char>(c)) || c == '.' ||
                                  c == '-' || c == ':' || c == '[' || c == ']';
                         });
      host = clean ? browser : "HOST";
    }
    return {host + ":" + std::to_string(context_.grpc_port), context_.grpc_tls};
  }

  // ---------------------------------------------------------------- routing

  httplib::Server::HandlerResponse Route(const httplib::Request& req, httplib::Response& res) {
    using R = httplib::Server::HandlerResponse;
    if (req.method == "POST") {
      const std::vector<std::string> s = Segments(req.path);
      const bool known = req.path == "/signin" || req.path == "/signout" ||
                         (s.size() == 3 && s[0] == "jobs" && IsJobId(s[1]) && s[2] == "cancel");
      if (known) return R::Unhandled;
      Html(res, 404, web::ErrorPage(Viewer{"", "", false}, 404, "Not found."));
      return R::Handled;
    }
    if (req.method != "GET" && req.method != "HEAD") {
      res.status = 405;
      res.set_header("Allow", "GET, HEAD, POST");
      return R::Handled;
    }
    Get(req, res);
    return R::Handled;
  }

  void Get(const httplib::Request& req, httplib::Response& res) {
    const std::string& path = req.path;
    if (path == "/static/app.css" || path == "/static/app.js") {
      const bool css = path.ends_with(".css");
      res.set_content(css ? web::embedded::kAppCss : web::embedded::kAppJs,
                      css ? "text/css; charset=utf-8" : "text/javascript; charset=utf-8");
      res.set_header("Cache-Control", "private, max-age=300");
      return;
    }
    if (path == "/signin") {
      if (SessionOf(req, res)) return Redirect(res, "/jobs");
      return Html(res, 200, web::SignInPage(""));
    }
    const std::vector<std::string> s = Segments(path);
    const bool fragment = (s.size() == 2 && s[0] == "jobs" && s[1] == "rows") ||
                          (s.size() == 3 && s[0] == "jobs" && s[2] == "status");
    const std::optional<Session> session = SessionOf(req, res);
    if (!session) {
      if (fragment) {
        res.status = 401;
        res.set_content("sign in first\n", "text/plain; charset=utf-8");
        return;
      }
      return Redirect(res, "/signin");
    }
    const Viewer viewer = ViewerOf(*session);
    if (path == "/" || path == "/jobs/") return Redirect(res, "/jobs");
    if (s[0] == "jobs") return JobRoutes(req, res, s, viewer);
    if (s[0] == "calibrations") return CalibrationRoutes(req, res, s, viewer);
    if (s[0] == "catalog") return CatalogRoutes(res, s, viewer);
    NotFound(res, viewer);
  }

  // ---------------------------------------------------------------- jobs

  // The filter of the job list from the query (?state=RUNNING&state=QUEUED&name=text); false with
  // the error page set for a bad value.
  bool ParseFilter(const httplib::Request& req, httplib::Response& res, const Viewer& viewer,
                   web::JobFilter* filter) {
    const size_t count = req.get_param_value_count("state");
    for (size_t i = 0; i < count && i < 16; ++i) {
      const std::string value = req.get_param_value("state", i);
      v1::JobState state;
      if (value.empty()) continue;
      if (!v1::JobState_Parse(value, &state) || state == v1::JOB_STATE_UNSPECIFIED) {
        Html(res, 400,
             web::ErrorPage(viewer, 400,
                            SpecError("state", MessageText(value, 64),
                                      "QUEUED, RUNNING, SUCCEEDED, FAILED, CANCELLED")
                                .what()));
        return false;
      }
      if (std::find(filter->states.begin(), filter->states.end(), state) == filter->states.end()) {
        filter->states.push_back(state);
      }
    }
    filter->name = req.get_param_value("name");
    if (filter->name.size() > kMaxNameFilterBytes) {
      Html(res, 400,
           web::ErrorPage(viewer, 400,
                          SpecError("name", std::to_string(filter->name.size()) + " bytes",
                                    "at most 256 bytes")
                              .what()));
      return false;
    }
    return true;
  }

  void JobRoutes(const httplib::Request& req, httplib::Response& res,
                 const std::vector<std::string>& s, const Viewer& viewer) {
    if (s.size() == 1 || (s.size() == 2 && s[1] == "rows")) {
      web::JobFilter filter;
      if (!ParseFilter(req, res, viewer, &filter)) return;
      v1::ListJobsRequest request;
      for (const v1::JobState state : filter.states) request.add_states(state);
      request.set_page_size(kListPageSize);
      request.set_name_contains(filter.name);
      v1::ListJobsResponse list;
      const grpc::Status status = context_.jobs->List(viewer.owner, request, &list);
      if (!status.ok()) {
        return Html(res, 400, web::ErrorPage(viewer, 400, status.error_message()));
      }
      if (s.size() == 1) return Html(res, 200, web::JobListPage(viewer, filter, list, Grpc(req)));
      bool active = false;
      Html(res, 200, web::JobRows(list, &active));
      res.set_header("X-Driftlab-Active", active ? "1" : "0");
      return;
    }
    if (!IsJobId(s[1]) || s.size() > 3) return NotFound(res, viewer);
    const std::string& id = s[1];
    v1::JobStatus status;
    // The owner check of every job route: Jobs.Get's (another owner's job is NOT_FOUND).
    if (!context_.jobs->Get(viewer.owner, id, &status).ok()) return NotFound(res, viewer);
    const std::string part = s.size() == 3 ? s[2] : "";
    if (part == "status") {
      Html(res, 200, web::JobStatusBlock(status));
      res.set_header("X-Driftlab-State", v1::JobState_Name(status.state()));
      return;
    }
    if (part == "report.html" || part == "result.json") {
      v1::JobResult result;
      const grpc::Status got = context_.jobs->GetResult(viewer.owner, id, &result);
      if (got.error_code() == grpc::StatusCode::NOT_FOUND) return NotFound(res, viewer);
      if (!got.ok()) return Html(res, 409, web::ErrorPage(viewer, 409, got.error_message()));
      if (part == "result.json") {
        return Download(res, app::JobResultToJson(result), "application/json", id + ".json");
      }
      const std::string html = app::RenderHtmlReport(result);
      res.set_header("Content-Security-Policy", ReportCsp(html));
      return Html(res, 200, html);
    }
    const std::optional<StoredJob> row = context_.store->Get(id);
    v1::SubmitJobRequest request;
    if (!row || row->owner != viewer.owner || !request.ParseFromString(row->request)) {
      return NotFound(res, viewer);
    }
    if (part == "job.json") {
      return Download(res, web::JobFileJson(request.job()), "application/json", id + "-job.json");
    }
    if (!part.empty()) return NotFound(res, viewer);
    web::JobView view{status, request, std::nullopt};
    if (status.state() == v1::SUCCEEDED) {
      v1::JobResult result;
      if (context_.jobs->GetResult(viewer.owner, id, &result).ok()) view.result = std::move(result);
    }
    Html(res, 200, web::JobPage(viewer, view, Grpc(req)));
  }

  void Cancel(const httplib::Request& req, httplib::Response& res, const std::string& id) {
    const std::optional<Session> session = SessionOf(req, res);
    if (!session) return Redirect(res, "/signin");
    const Viewer viewer = ViewerOf(*session);
    if (!FormAllowed(req, *session, ParseForm(req.body))) {
      spdlog::warn("web: cancel of {} refused: no valid form token (owner={} client={})",
                   MessageText(id, 64), session->owner, req.remote_addr);
      return Html(res, 403,
                  web::ErrorPage(viewer, 403,
                                 "The form token is missing or wrong: reload the page and try "
                                 "again."));
    }
    v1::JobStatus status;
    const grpc::Status cancelled = context_.jobs->Cancel(viewer.owner, id, &status);
    if (cancelled.error_code() == grpc::StatusCode::NOT_FOUND) return NotFound(res, viewer);
    if (!cancelled.ok()) {
      return Html(res, 500, web::ErrorPage(viewer, 500, cancelled.error_message()));
    }
    spdlog::info("web: job={} cancelled by owner={}", id, viewer.owner);
    Redirect(res, "/jobs/" + id);
  }

  // ---------------------------------------------------------------- calibrations, catalogue

  void CalibrationRoutes(const httplib::Request& req, httplib::Response& res,
                         const std::vector<std::string>& s, const Viewer& viewer) {
    if (s.size() == 1) {
      return Html(res, 200,
                  web::CalibrationListPage(
                      viewer, context_.store->ListCalibrations(viewer.owner, 0, kListPageSize)));
    }
    if (!IsCalibrationId(s[1]) || s.size() > 3) return NotFound(res, viewer);
    std::optional<StoredCalibration> record = context_.store->GetCalibration(s[1]);
    // Another owner's record is not found, as another owner's job.
    if (!record || record->owner != viewer.owner) return NotFound(res, viewer);
    const std::string part = s.size() == 3 ? s[2] : "";
    std::optional<std::string> body;
    if (part.empty()) {
      const std::string html = web::CalibrationPage(viewer, *record, Grpc(req));
      if (!html.empty()) return Html(res, 200, html);
    } else if (part == "result.json" && (body = web::CalibrationResultJson(*record))) {
      return Download(res, *body, "application/json", record->id + ".json");
    } else if (part == "settings.json" && (body = web::CalibrationSettingsJson(*record))) {
      return Download(res, *body, "application/json", record->id + "-settings.json");
    } else if (part == "report.html" && (body = web::CalibrationReport(*record))) {
      res.set_header("Content-Security-Policy", ReportCsp(*body));
      return Html(res, 200, *body);
    } else if (part != "result.json" && part != "settings.json" && part != "report.html") {
      return NotFound(res, viewer);
    }
    Html(res, 500, web::ErrorPage(viewer, 500, "The stored record cannot be read."));
  }

  void CatalogRoutes(httplib::Response& res, const std::vector<std::string>& s,
                     const Viewer& viewer) {
    if (s.size() == 1) return Html(res, 200, web::CatalogPage(viewer, PresetSummaries()));
    if (s.size() > 3 || s[1].size() > 64) return NotFound(res, viewer);
    const std::optional<v1::Preset> preset = FindPreset(s[1]);
    if (!preset) return NotFound(res, viewer);
    if (s.size() == 2) return Html(res, 200, web::PresetPage(viewer, *preset));
    if (s[2] == "sensor.json") {
      return Download(res, web::PresetSensorJson(*preset), "application/json",
                      preset->summary().name() + "-sensor.json");
    }
    NotFound(res, viewer);
  }

  // ---------------------------------------------------------------- sign-in

  void SignIn(const httplib::Request& req, httplib::Response& res) {
    const std::string& client = req.remote_addr;
    if (!SameOrigin(req)) {
      return Html(res, 403, web::SignInPage("Sign-in from another site refused."));
    }
    if (!throttle_.Allowed(client)) {
      const int retry = throttle_.RetryAfterSeconds(client);
      spdlog::warn("web: sign-in refused: too many failed tries (client={})", client);
      res.set_header("Retry-After", std::to_string(retry));
      return Html(res, 429,
                  web::SignInPage(fmt::format("Too many failed sign-ins from this address: try "
                                              "again in {} s.",
                                              retry)));
    }
    const std::map<std::string, std::string> form = ParseForm(req.body);
    const auto token = form.find("token");
    std::string owner;
    if (token == form.end() || token->second.empty() ||
        !context_.auth->AuthenticateHeader("Bearer " + token->second, &owner).ok()) {
      throttle_.Failed(client);
      spdlog::warn("web: sign-in failed: unknown token (client={})", client);
      return Html(res, 401, web::SignInPage("Unknown token."));
    }
    SetSessionCookie(res, sessions_.Create(owner));
    spdlog::info("web: owner={} signed in (client={})", owner, client);
    Redirect(res, "/jobs");
  }

  void SignOut(const httplib::Request& req, httplib::Response& res) {
    const std::optional<Session> session = SessionOf(req, res);
    if (!session) return Redirect(res, "/signin");
    if (!FormAllowed(req, *session, ParseForm(req.body))) {
      return Html(res, 403,
                  web::ErrorPage(ViewerOf(*session), 403,
                                 "The form token is missing or wrong: reload the page."));
    }
    sessions_.Remove(CookieValue(req));
    res.set_header("Set-Cookie", cookie_name_ + "=; Path=/; Max-Age=0; HttpOnly; SameSite=Lax" +
                                     std::string(secure_ ? "; Secure" : ""));
    Redirect(res, "/signin");
  }

  WebOptions options_;
  WebContext context_;
  web::SessionStore sessions_;
  web::SignInThrottle throttle_;
  std::unique_ptr<web::TlsContext> tls_;
  bool secure_ = false;
  std::string cookie_name_;
  std::unique_ptr<web::BoundedHttpServer> http_;
  std::thread thread_;
  int port_ = 0;
  bool stopped_ = false;
};

namespace web {

std::string SignInPage(const std::string& message) {
  std::string body =
      "<div class=\"signin\"><h1>Sign in</h1>\n<p>With a token of this server's tokens file "
      "(the one <code>driftlab --token</code> or <code>DRIFTLAB_TOKEN</code> uses).</p>\n";
  if (!message.empty()) body += "<p class=\"error\">" + Escape(message) + "</p>\n";
  body +=
      "<form method=\"post\" action=\"/signin\"><label>Token<input type=\"password\" "
      "name=\"token\" autocomplete=\"current-password\" required autofocus></label>"
      "<button type=\"submit\">Sign in</button></form></div>\n";
  return Page("Sign in", "", Viewer{"", "", false}, body);
}

std::string ErrorPage(const Viewer& viewer, int status, const std::string& message) {
  return Page(std::to_string(status), "", viewer,
              "<h1>" + std::to_string(status) + "</h1>\n<p>" + Escape(message) +
                  "</p>\n<p><a href=\"/jobs\">Jobs</a></p>\n");
}

}  // namespace web

WebServer::WebServer(const WebOptions& options, const WebContext& context)
    : impl_(std::make_unique<Impl>(options, context)) {}
WebServer::~WebServer() = default;
int WebServer::port() const { return impl_->port(); }
void WebServer::Stop() { impl_->Stop(); }

}  // namespace driftlab::server
