// The job list and the job page.
#include <fmt/format.h>
#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <cmath>

#include "driftlab/app/consistency_check.h"
#include "web/pages.h"

namespace driftlab::server::web {
namespace {

std::string StateBadge(v1::JobState state) {
  const std::string name = v1::JobState_Name(state);
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
  return "<span class=\"state " + lower + "\">" + name + "</span>";
}

double Fraction(const v1::JobStatus& s) {
  if (s.state() == v1::SUCCEEDED) return 1.0;
  if (s.samples_total() == 0) return 0.0;
  return std::clamp(static_cast<double>(s.samples_done()) / static_cast<double>(s.samples_total()),
                    0.0, 1.0);
}

// Seconds left at the current speed; none before the job runs or before its first progress.
std::optional<double> SecondsLeft(const v1::JobStatus& s) {
  if (s.state() != v1::RUNNING || !(s.samples_per_s() > 0.0)) return std::nullopt;
  const double left =
      static_cast<double>(s.samples_total() - std::min(s.samples_total(), s.samples_done()));
  return left / s.samples_per_s();
}

std::string Progress(const v1::JobStatus& s) {
  const double fraction = Fraction(s);
  return fmt::format(
      "<progress max=\"1000\" value=\"{}\"></progress> <span class=\"pct\">{:.1f} %</span> "
      "<span class=\"runs\">{} / {} runs</span>",
      static_cast<int>(std::lround(fraction * 1000)), 100.0 * fraction, s.runs_done(),
      s.runs_total());
}

std::string TimeLeft(const v1::JobStatus& s) {
  const std::optional<double> left = SecondsLeft(s);
  if (left) return FormatDuration(*left);
  return s.state() == v1::QUEUED ? "waiting" : "–";
}

std::optional<double> Optional(bool has, double value) {
  return has ? std::optional<double>(value) : std::nullopt;
}

std::string JobHref(const std::string& id) { return "/jobs/" + UrlEncode(id); }

std::string FilterForm(const JobFilter& filter) {
  std::string html =
      "<form class=\"filters\" method=\"get\" action=\"/jobs\">\n<fieldset><legend>State"
      "</legend>";
  for (const v1::JobState state :
       {v1::QUEUED, v1::RUNNING, v1::SUCCEEDED, v1::FAILED, v1::CANCELLED}) {
    const bool on =
        std::find(filter.states.begin(), filter.states.end(), state) != filter.states.end();
    const std::string name = v1::JobState_Name(state);
    html += fmt::format(
        "<label><input type=\"checkbox\" name=\"state\" value=\"{0}\"{1}> {0}"
        "</label>",
        name, on ? " checked" : "");
  }
  html += "</fieldset>\n<label>Name contains <input type=\"search\" name=\"name\" value=\"" +
          Escape(filter.name) +
          "\" maxlength=\"256\"></label>\n<button type=\"submit\">Filter</button> "
          "<a href=\"/jobs\">Clear</a>\n</form>\n";
  return html;
}

std::string QueryOf(const JobFilter& filter) {
  std::string query;
  for (const v1::JobState state : filter.states) {
    query += (query.empty() ? "?" : "&") + std::string("state=") + v1::JobState_Name(state);
  }
  if (!filter.name.empty())
    query += (query.empty() ? "?" : "&") + ("name=" + UrlEncode(filter.name));
  return query;
}

// The overrides of the request as CLI options: " --runs 20 --seed 7".
std::string OverrideOptions(const v1::SubmitJobRequest& request, bool with_deadline) {
  std::string options;
  if (request.has_runs()) options += fmt::format(" --runs {}", request.runs());
  if (request.has_seed()) options += fmt::format(" --seed {}", request.seed());
  if (!request.shard().empty()) options += " --shard " + request.shard();
  if (with_deadline && request.has_deadline_s() && request.deadline_s() > 0) {
    options += fmt::format(" --deadline {}", request.deadline_s());
  }
  return options;
}

std::string ResultSection(const v1::JobStatus& status, const v1::JobResult& result) {
  const std::string href = JobHref(status.job_id());
  std::string html = "<section class=\"result\"><h2>Result</h2>\n<p class=\"actions\">";
  html += "<a class=\"button\" href=\"" + href +
          "/report.html\" target=\"_blank\" rel=\"noopener\">"
          "Open the report</a> ";
  html += "<a class=\"button\" href=\"" + href +
          "/result.json\" download>Download the result "
          "(JSON)</a></p>\n";
  const app::ConsistencyVerdict verdict = app::AssessConsistency(result);
  if (verdict.tested()) {
    html += fmt::format("<p class=\"verdict {}\"><b>Consistency:</b> {}</p>\n",
                        verdict.consistent() ? "ok" : "bad", Escape(verdict.Summary()));
  } else {
    html +=
        "<p class=\"verdict none\"><b>Consistency:</b> not tested (the job has no filter and "
        "no covariance analysis)</p>\n";
  }
  html += "</section>\n";
  return html;
}

std::string CommandsSection(const v1::JobStatus& status, const v1::SubmitJobRequest& request,
                            const GrpcTarget& grpc) {
  const std::string remote = " --server " + grpc.address + (grpc.tls ? " --tls-ca CA.pem" : "");
  const std::string job_file = status.job_id() + "-job.json";
  std::string html =
      "<section class=\"commands\"><h2>From the command line</h2>\n"
      "<p>With your token in the environment (<code>export DRIFTLAB_TOKEN=…</code>)" +
      std::string(grpc.tls ? " and the certificate authority of the server in CA.pem" : "") +
      ":</p>\n";
  if (status.state() == v1::SUCCEEDED) {
    html += "<p>Fetch the result and write its report:</p>\n" +
            Command("driftlab result " + status.job_id() + remote +
                    " --out result.json --report report.html");
  } else if (!IsFinal(status.state())) {
    html += "<p>Follow it:</p>\n" + Command("driftlab watch " + status.job_id() + remote);
  }
  html += "<p>Rerun it with the <a href=\"" + JobHref(status.job_id()) +
          "/job.json\" download>job file</a> (" + Escape(job_file) +
          "), on this server or in-process (same result, bit for bit, apart from timings):</p>\n" +
          Command("driftlab submit " + job_file + remote + OverrideOptions(request, true)) +
          Command("driftlab run " + job_file + OverrideOptions(request, false) +
                  " --out result.json --report report.html") +
          "</section>\n";
  return html;
}

std::string RequestSection(const v1::JobStatus& status, const v1::SubmitJobRequest& request) {
  std::string html = "<section class=\"jobfile\"><h2>Job file</h2>\n";
  std::vector<std::string> overrides;
  if (request.has_runs()) overrides.push_back(fmt::format("runs {}", request.runs()));
  if (request.has_seed()) overrides.push_back(fmt::format("seed {}", request.seed()));
  if (!request.shard().empty()) overrides.push_back("shard " + Escape(request.shard()));
  if (request.has_deadline_s() && request.deadline_s() > 0) {
    overrides.push_back("deadline " + FormatDuration(request.deadline_s()));
  }
  if (!overrides.empty()) {
    html += "<p>Submitted with " + fmt::format("{}", fmt::join(overrides, ", ")) + ".</p>\n";
  }
  html += "<p><a href=\"" + JobHref(status.job_id()) +
          "/job.json\" download>Download the job "
          "file</a></p>\n" +
          JsonTree(JobFileJson(request.job()), 1) + "</section>\n";
  return html;
}

}  // namespace

bool IsFinal(v1::JobState state) {
  return state == v1::SUCCEEDED || state == v1::FAILED || state == v1::CANCELLED;
}

std::string JobFileJson(const v1::Job& job) {
  google::protobuf::util::JsonPrintOptions print;
  print.add_whitespace = true;
  print.preserve_proto_field_names = true;
  std::string json;
  if (!google::protobuf::util::MessageToJsonString(job, &json, print).ok()) return "{}\n";
  return json;
}

std::string JobRows(const v1::ListJobsResponse& jobs, bool* active) {
  *active = false;
  std::string html;
  for (const v1::JobStatus& s : jobs.jobs()) {
    *active = *active || !IsFinal(s.state());
    const std::string name = s.name().empty() ? "(no name)" : s.name();
    html += fmt::format(
        "<tr data-job=\"{0}\" data-state=\"{1}\"><td class=\"name\"><a href=\"{2}\">{3}</a>"
        "<div class=\"id\">{0}</div></td><td>{4}</td><td class=\"time\">{5}</td>"
        "<td class=\"time\">{6}</td><td class=\"time\">{7}</td><td class=\"progress\">{8}</td>"
        "<td class=\"left\">{9}</td><td class=\"num\">{10}</td><td class=\"num\">{11}</td>"
        "<td class=\"cluster\">{12}</td></tr>\n",
        Escape(s.job_id()), v1::JobState_Name(s.state()), JobHref(s.job_id()), Escape(name),
        StateBadge(s.state()), FormatUtc(Optional(s.has_submitted_unix_s(), s.submitted_unix_s())),
        FormatUtc(Optional(s.has_started_unix_s(), s.started_unix_s())),
        FormatUtc(Optional(s.has_finished_unix_s(), s.finished_unix_s())), Progress(s), TimeLeft(s),
        FormatCount(s.runs_total()), FormatCount(s.samples_total()),
        s.cluster().empty() ? "–" : Escape(s.cluster()));
  }
  if (jobs.jobs().empty()) {
    html =
        "<tr><td colspan=\"10\" class=\"empty\">No jobs match (the commands below the table "
        "submit one).</td></tr>\n";
  }
  return html;
}

std::string JobListPage(const Viewer& viewer, const JobFilter& filter,
                        const v1::ListJobsResponse& jobs, const GrpcTarget& grpc) {
  bool active = false;
  const std::string rows = JobRows(jobs, &active);
  std::string body = "<h1>Jobs</h1>\n" + FilterForm(filter);
  body += fmt::format(
      "<table class=\"jobs\"><thead><tr><th>Name</th><th>State</th><th>Submitted</th>"
      "<th>Started</th><th>Finished</th><th>Progress</th><th>Time left</th><th>Runs</th>"
      "<th>Samples</th><th>Cluster</th></tr></thead>\n<tbody data-poll=\"/jobs/rows{}\" "
      "data-active=\"{}\">\n{}</tbody></table>\n",
      Escape(QueryOf(filter)), active ? "1" : "0", rows);
  if (!jobs.next_page_token().empty()) {
    body +=
        "<p class=\"note\">The newest 100 jobs are shown; narrow the list with the filters "
        "(<code>driftlab jobs</code> lists all).</p>\n";
  }
  body +=
      "<noscript><p class=\"note\">Without JavaScript the list does not refresh by itself: "
      "reload the page.</p></noscript>\n";
  const std::string remote = " --server " + grpc.address + (grpc.tls ? " --tls-ca CA.pem" : "");
  body +=
      "<section class=\"commands\"><h2>From the command line</h2>\n"
      "<p>With your token in the environment (<code>export DRIFTLAB_TOKEN=…</code>)" +
      std::string(grpc.tls ? " and the certificate authority of the server in CA.pem" : "") +
      ", submit a job file and list your jobs:</p>\n" +
      Command("driftlab submit JOB.json" + remote) + Command("driftlab jobs" + remote) +
      "</section>\n";
  return Page("Jobs", "jobs", viewer, body);
}

std::string JobStatusBlock(const v1::JobStatus& s) {
  std::string html = "<table class=\"facts\">\n";
  const auto row = [&](const std::string& key, const std::string& value) {
    html += "<tr><th>" + key + "</th><td>" + value + "</td></tr>\n";
  };
  row("State", StateBadge(s.state()));
  if (!s.error().empty()) row("Error", "<span class=\"error\">" + Escape(s.error()) + "</span>");
  row("Progress", Progress(s));
  row("Samples", FormatCount(s.samples_done()) + " / " + FormatCount(s.samples_total()));
  if (s.state() == v1::RUNNING && s.samples_per_s() > 0) {
    row("Speed", FormatCount(static_cast<uint64_t>(s.samples_per_s())) + " samples/s");
  }
  row("Time left", TimeLeft(s));
  row("Submitted", FormatUtc(Optional(s.has_submitted_unix_s(), s.submitted_unix_s())));
  row("Started", FormatUtc(Optional(s.has_started_unix_s(), s.started_unix_s())));
  row("Finished", FormatUtc(Optional(s.has_finished_unix_s(), s.finished_unix_s())));
  if (s.has_elapsed_s()) row("Elapsed", FormatDuration(s.elapsed_s()));
  row("Attempts", std::to_string(s.attempts()));
  if (!s.cluster().empty()) row("Cluster", "<code>" + Escape(s.cluster()) + "</code>");
  html += "</table>\n";
  return html;
}

std::string JobPage(const Viewer& viewer, const JobView& job, const GrpcTarget& grpc) {
  const v1::JobStatus& s = job.status;
  const std::string name = s.name().empty() ? "(no name)" : s.name();
  std::string body =
      "<h1>" + Escape(name) + "</h1>\n<p class=\"id\">" + Escape(s.job_id()) + "</p>\n";
  if (!job.request.job().description().empty()) {
    body += "<p class=\"description\">" + Escape(job.request.job().description()) + "</p>\n";
  }
  body += fmt::format(
      "<section class=\"status\" data-poll=\"{}/status\" data-state=\"{}\">\n{}"
      "</section>\n",
      JobHref(s.job_id()), v1::JobState_Name(s.state()), JobStatusBlock(s));
  if (!IsFinal(s.state())) {
    body += "<form class=\"cancel\" method=\"post\" action=\"" + JobHref(s.job_id()) +
            "/cancel\"><input type=\"hidden\" name=\"csrf\" value=\"" + Escape(viewer.csrf) +
            "\"><button type=\"submit\" class=\"danger\">Cancel this job</button></form>\n";
    body +=
        "<noscript><p class=\"note\">Without JavaScript the progress does not refresh by "
        "itself: reload the page.</p></noscript>\n";
  }
  if (job.result) body += ResultSection(s, *job.result);
  body += CommandsSection(s, job.request, grpc);
  body += RequestSection(s, job.request);
  return Page(name, "jobs", viewer, body);
}

}  // namespace driftlab::server::web
