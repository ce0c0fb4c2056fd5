// lucent bench store: trial commits per second and commit latency (p50, p99) of each
// study store backend with 1, 8 and 50 concurrent writers (stations), each its own
// connection, participant and session, measured in one run on this machine.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <thread>
#include <vector>

#include "app/commands.h"
#include "app/nginx_proxy.h"
#include "app/serve_http.h"
#include "study/postgres/local_server.h"
#include "study/protocol.h"
#include "study/serve/web_study.h"
#include "study/sqlite/database.h"
#include "study/sqlite/sqlite_store.h"
#include "study/store_pool.h"
#include "study/study_store.h"
#include "study/trial_plan.h"

namespace lucent::app {
namespace {

struct BenchRow {
    std::string backend;
    int writers = 0;
    int commits = 0;
    double seconds = 0;  // the commit phase: first commit's start to the last one's end
    double p50_ms = 0, p99_ms = 0;
    int failed_writers =
        0;  // writers that stopped on an error (e.g. SQLite's busy timeout)
    std::string first_error;
    int instances = 0;  // serve instances behind the proxy (0: not such a row)
    // The machine's CPUs busy over the row (0..1), and of that this process's share (the
    // serve instances and the simulated browsers); -1: not measured.
    double cpu_busy = -1;
    double cpu_self = -1;
};

// The machine's CPU time so far (/proc/stat's first line, in clock ticks): busy and all.
struct CpuTimes {
    double busy = 0, total = 0;
    double self = 0;  // this process's (the instances and the browsers), in ticks
};
CpuTimes cpu_times() {
    std::ifstream stat("/proc/stat");
    std::string cpu;
    double user = 0, nice = 0, system = 0, idle = 0, iowait = 0, irq = 0, softirq = 0,
           steal = 0;
    stat >> cpu >> user >> nice >> system >> idle >> iowait >> irq >> softirq >> steal;
    CpuTimes t;
    t.busy = user + nice + system + irq + softirq + steal;
    t.total = t.busy + idle + iowait;
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    const double seconds = usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
                           1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
    t.self = seconds * static_cast<double>(sysconf(_SC_CLK_TCK));
    return t;
}
// Of the busy time between two readings, the share of this process (the rest: the
// PostgreSQL server, nginx, anything else running).
double self_share(const CpuTimes& before, const CpuTimes& after) {
    const double busy = after.busy - before.busy;
    return busy > 0 ? std::clamp((after.self - before.self) / busy, 0.0, 1.0) : -1;
}
double busy_fraction(const CpuTimes& before, const CpuTimes& after) {
    const double total = after.total - before.total;
    return total > 0 ? (after.busy - before.busy) / total : -1;
}

// Commits per second; 0 for a row without commits (never Inf or NaN in the table).
double rate(const BenchRow& r) { return r.seconds > 0 ? r.commits / r.seconds : 0.0; }

double percentile(std::vector<double> v, double q) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const size_t i =
        std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5));
    return v[i];
}

// What each writer measured: commit latencies, its first and last commit, and why it
// stopped early ("" when it did not).
struct WriterTimes {
    using Clock = std::chrono::steady_clock;
    explicit WriterTimes(int writers)
        : latencies(writers),
          first_start(writers, Clock::time_point::max()),
          last_end(writers, Clock::time_point::min()),
          errors(writers) {}
    std::vector<std::vector<double>> latencies;
    std::vector<Clock::time_point> first_start, last_end;
    std::vector<std::string> errors;

    // Writer w's commit that started at t0 and was confirmed at t1.
    void record(int w, Clock::time_point t0, Clock::time_point t1) {
        first_start[w] = std::min(first_start[w], t0);
        last_end[w] = std::max(last_end[w], t1);
        latencies[w].push_back(
            std::chrono::duration<double, std::milli>(t1 - t0).count());
    }
};

// Runs writer(w, times) for every w at once, one thread each; a writer that throws
// stops there with its message in times.errors[w].
WriterTimes time_writers(int writers,
                         const std::function<void(int w, WriterTimes& times)>& writer) {
    WriterTimes times(writers);
    std::vector<std::thread> threads;
    for (int w = 0; w < writers; ++w) {
        threads.emplace_back([&, w] {
            try {
                writer(w, times);
            } catch (const std::exception& e) {
                times.errors[w] = e.what();
            }
        });
    }
    for (std::thread& t : threads) t.join();
    return times;
}

// One row of the table: commits per second over the span of all writers, p50/p99.
BenchRow summarise(const std::string& backend, const WriterTimes& times) {
    BenchRow row;
    row.backend = backend;
    row.writers = static_cast<int>(times.errors.size());
    const auto begin =
        *std::min_element(times.first_start.begin(), times.first_start.end());
    const auto end = *std::max_element(times.last_end.begin(), times.last_end.end());
    row.seconds = end > begin ? std::chrono::duration<double>(end - begin).count() : 0.0;
    std::vector<double> all;
    for (std::size_t w = 0; w < times.errors.size(); ++w) {
        if (!times.errors[w].empty() && row.failed_writers++ == 0)
            row.first_error = times.errors[w];
        all.insert(all.end(), times.latencies[w].begin(), times.latencies[w].end());
    }
    row.commits = static_cast<int>(all.size());
    row.p50_ms = percentile(all, 0.50);
    row.p99_ms = percentile(all, 0.99);
    return row;
}

// `writers` stations at once, each answering `trials` trials of its own session.
BenchRow run_writers(const std::string& backend, const std::string& db, int writers,
                     int trials, const std::string& journal_dir) {
    const study::Protocol protocol = study::builtin_protocol("thesis");
    {
        auto store =
            study::open_study_store(db);  // the study row, before the clock starts
        store->ensure_study(protocol);
    }
    using Clock = WriterTimes::Clock;
    const WriterTimes times = time_writers(writers, [&](int w, WriterTimes& measured) {
        study::StoreOptions options;
        options.journal_path = journal_dir + "/journal-" + std::to_string(w) + ".db";
        auto store = study::open_study_store(db, options);
        const int64_t study_id = store->ensure_study(protocol);
        const std::string code =
            "bench" + std::to_string(writers) + "w" + std::to_string(w);
        int number = 0;
        const int64_t pid = store->ensure_participant(study_id, code, &number);
        const study::SessionRow s = store->create_session(
            study_id, pid, study::plan_trials(protocol, 1000 + w, number), 1000 + w, {});
        const std::vector<study::TrialRow> rows = store->trials(s.id);
        const int n = std::min<int>(trials, static_cast<int>(rows.size()));
        for (int i = 0; i < n; ++i) {
            study::TrialOutcome o;
            o.onset_ns = 1;
            o.confirm_ns = 2;
            for (const study::Question& q : protocol.questions)
                o.responses.push_back(
                    {q.id, rows[i].is_catch ? rows[i].expected : 1 + (i % q.points()),
                     500.0, 0, 1, 2});
            const auto t0 = Clock::now();
            store->record_trial(s.id, rows[i].id, o);
            measured.record(w, t0, Clock::now());
        }
        if (store->pending_trials() != 0)
            measured.errors[w] =
                std::to_string(store->pending_trials()) + " trials unconfirmed";
    });
    return summarise(backend, times);
}

// An in-process `lucent serve` instance: a pool of store connections without the
// journal, the core and the HTTP server on a loopback port, as a `lucent serve` process
// runs them (without pictures to serve).
class BenchInstance {
public:
    BenchInstance(const study::Protocol& protocol, const std::string& db,
                  size_t connections, const study::WebStudyOptions& options,
                  const std::map<std::string, ServedPicture>& pictures, int threads) {
        study::StoreOptions store_options;
        store_options.journal = false;
        pool_ = std::make_unique<study::StorePool>(db, connections, store_options,
                                                   std::chrono::seconds(2));
        web_ = std::make_unique<study::WebStudy>(protocol, *pool_, options);
        configure_serve_http(http_, *web_, pictures, threads);
        port_ = bind_serve_port(http_, "127.0.0.1", 0);
        if (port_ < 0)
            throw study::StoreError("cannot listen on 127.0.0.1 for the serve rows");
        thread_ = std::thread([this] { http_.listen_after_bind(); });
        while (!http_.is_running())
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    ~BenchInstance() {
        http_.stop();
        thread_.join();
    }
    int port() const { return port_; }

private:
    std::unique_ptr<study::StorePool> pool_;
    std::unique_ptr<study::WebStudy> web_;
    httplib::Server http_;
    std::thread thread_;
    int port_ = 0;
};

// `writers` browsers at once against `port` on loopback (an instance, or the proxy in
// front of several), each a participant answering `trials` trials; a commit's latency is
// the whole /api/answer round trip (request, checks, replay, the store's commit, the
// reply).
WriterTimes drive_pages(const study::Protocol& protocol, int port, int writers,
                        int trials, const std::string& code_prefix, int think_ms = 0) {
    using nlohmann::json;
    using Clock = WriterTimes::Clock;
    return time_writers(writers, [&](int w, WriterTimes& measured) {
        httplib::Client client("127.0.0.1", port);
        client.set_keep_alive(true);
        client.set_tcp_nodelay(true);  // as browsers do
        client.set_read_timeout(60);
        double now = 10;  // the simulated page's performance.now()
        auto post = [&](const std::string& endpoint, json body) {
            // A busy or restarting server is asked again, as the page does.
            for (int attempt = 0;; ++attempt) {
                const auto r = client.Post(("/api/" + endpoint).c_str(), body.dump(),
                                           "application/json");
                if (r && r->status == 200) return json::parse(r->body);
                const bool transient =
                    !r || r->status == 502 || r->status == 503 || r->status == 504;
                if (!transient || attempt == 20)
                    throw std::runtime_error(
                        endpoint + ": " + (r ? r->body : httplib::to_string(r.error())));
                std::this_thread::sleep_for(
                    std::chrono::milliseconds(50 << std::min(attempt, 4)));
            }
        };
        json state = post(
            "session", {{"participant", code_prefix + std::to_string(w)}, {"t_ms", now}});
        const std::string token = state["token"];
        int answered = 0;
        while (state["screen"] != "done" && answered < trials) {
            if (state["screen"] != "trial") {
                now += 100;
                state = post("continue", {{"token", token},
                                          {"view", state["view"]},
                                          {"shown_ms", now - 50},
                                          {"t_ms", now}});
                continue;
            }
            const double onset = now + state["trial"]["blank_ms"].get<double>() + 10;
            json events = json::array();
            const bool is_catch = !state["trial"]["prompt"].get<std::string>().empty();
            for (size_t q = 0; q < protocol.questions.size(); ++q)
                events.push_back({{"t_ms", onset + 100.0 * (q + 1)},
                                  {"type", "point"},
                                  {"question", q},
                                  {"value", is_catch ? protocol.catch_trials[0].expected
                                                     : 1 + (answered + int(q)) % 7}});
            events.push_back({{"t_ms", onset + 400}, {"type", "next"}});
            now = onset + 1000;
            // The participant looks and decides (not timed); pages start out of step.
            if (think_ms > 0)
                std::this_thread::sleep_for(std::chrono::milliseconds(
                    answered == 0 ? (w * 7919) % think_ms : think_ms));
            const auto t0 = Clock::now();
            state = post("answer", {{"token", token},
                                    {"trial", state["trial"]["id"]},
                                    {"view", state["view"]},
                                    {"onset_ms", onset},
                                    {"events", events}});
            measured.record(w, t0, Clock::now());
            ++answered;
        }
    });
}

// What every serve row's instances share: the thesis protocol, its pictures' sizes.
struct ServeSetup {
    study::Protocol protocol = study::builtin_protocol("thesis");
    study::WebStudyOptions options;
    std::map<std::string, ServedPicture> pictures;
    ServeSetup() {
        options.secret = "bench";
        for (const Stimulus& s : protocol.stimuli) {
            options.images[s.id] = {protocol.stimulus_width, protocol.stimulus_height};
            pictures[s.id] = {"", options.images[s.id]};
        }
    }
};

// One `lucent serve` (its own pool: 4 connections to a server, 1 to a file) answering
// `writers` browsers directly.
BenchRow run_serve_writers(const std::string& backend, const std::string& db, int writers,
                           int trials) {
    const ServeSetup setup;
    const BenchInstance instance(setup.protocol, db, study::is_server_uri(db) ? 4 : 1,
                                 setup.options, setup.pictures, std::max(8, writers + 4));
    return summarise(backend, drive_pages(setup.protocol, instance.port(), writers,
                                          trials, "web" + std::to_string(writers) + "w"));
}

// `instances` serve instances (each as `lucent serve` runs: 4 store connections, 64 HTTP
// workers) on one PostgreSQL database behind Debian's nginx (round robin), `writers`
// browsers through the proxy.
BenchRow run_instance_writers(const std::string& db, int instances, int writers,
                              int trials, int think_ms) {
    const ServeSetup setup;
    std::vector<std::unique_ptr<BenchInstance>> running;
    std::vector<int> ports;
    for (int i = 0; i < instances; ++i) {
        running.push_back(std::make_unique<BenchInstance>(
            setup.protocol, db, 4, setup.options, setup.pictures, 64));
        ports.push_back(running.back()->port());
    }
    NginxProxy proxy(ports);
    const CpuTimes before = cpu_times();
    BenchRow row = summarise(
        "serve x" + std::to_string(instances) + " behind nginx + postgresql",
        drive_pages(setup.protocol, proxy.port(), writers, trials,
                    "i" + std::to_string(instances) + "p" + std::to_string(writers) + "w",
                    think_ms));
    const CpuTimes after = cpu_times();
    row.cpu_busy = busy_fraction(before, after);
    row.cpu_self = self_share(before, after);
    return row;
}

int run_bench_store(const std::vector<int>& writer_counts, int trials,
                    const std::vector<int>& instance_counts,
                    const std::vector<int>& participant_counts, int think_ms,
                    const std::string& server, const std::string& csv) {
    namespace fs = std::filesystem;
    std::string pattern =
        (fs::temp_directory_path() / "lucent-bench-store-XXXXXX").string();
    if (!mkdtemp(pattern.data()))
        throw study::StoreError("cannot create a scratch folder");
    const std::string scratch = pattern;
    std::vector<BenchRow> rows, serve_rows, instance_rows;
    {
        std::unique_ptr<study::LocalPostgres> local;
        if (server.empty()) local = std::make_unique<study::LocalPostgres>();
        int k = 0;
        for (int writers : writer_counts) {
            const std::string file = scratch + "/w" + std::to_string(writers) + ".db";
            rows.push_back(run_writers("sqlite (WAL, synchronous=FULL)", file, writers,
                                       trials, scratch));
            std::string uri = server;
            if (local) uri = local->create_database("bench_" + std::to_string(k++));
            study::init_study_store(uri);
            rows.push_back(
                run_writers(local ? "postgresql (unix socket)" : "postgresql " + server,
                            uri, writers, trials, scratch));
        }
        // lucent serve's round trips over loopback HTTP, into each backend.
        for (int writers : writer_counts) {
            const std::string file =
                scratch + "/serve-w" + std::to_string(writers) + ".db";
            serve_rows.push_back(run_serve_writers("serve + sqlite (HTTP round trip)",
                                                   file, writers, trials));
            std::string uri = server;
            if (local) uri = local->create_database("bench_serve_" + std::to_string(k++));
            study::init_study_store(uri);
            serve_rows.push_back(
                run_serve_writers(local ? "serve + postgresql (HTTP round trip)"
                                        : "serve + postgresql " + server,
                                  uri, writers, trials));
        }
        // Several instances on one database behind Debian's nginx (issue 32).
        if (!NginxProxy::available()) {
            std::printf("no rows for instances behind a proxy: %s is not installed\n",
                        NginxProxy::kBinary);
        } else {
            for (int instances : instance_counts) {
                for (int participants : participant_counts) {
                    std::string uri = server;
                    if (local) {
                        uri = local->create_database("bench_instances_" +
                                                     std::to_string(k++));
                        study::init_study_store(uri);
                    }
                    instance_rows.push_back(run_instance_writers(
                        uri, instances, participants, trials, think_ms));
                    instance_rows.back().instances = instances;
                }
            }
        }
    }
    std::error_code ec;
    fs::remove_all(scratch, ec);

    std::vector<BenchRow> all_rows = rows;
    all_rows.insert(all_rows.end(), serve_rows.begin(), serve_rows.end());
    all_rows.insert(all_rows.end(), instance_rows.begin(), instance_rows.end());
    // cpu: the machine's CPUs busy over the row, and of that the share of this process
    // (the serve instances and the simulated browsers; the rest is PostgreSQL and nginx).
    std::printf("%-42s %7s %8s %9s %10s %8s %8s %7s %12s\n", "backend", "writers",
                "commits", "seconds", "commits/s", "p50 ms", "p99 ms", "failed",
                "cpu (ours)");
    for (const BenchRow& r : all_rows) {
        char cpu[32] = "-";
        if (r.cpu_busy >= 0)
            std::snprintf(cpu, sizeof cpu, "%.0f%% (%.0f%%)", 100 * r.cpu_busy,
                          100 * std::max(0.0, r.cpu_self));
        std::printf("%-42s %7d %8d %9.3f %10.1f %8.3f %8.3f %7d %12s\n",
                    r.backend.c_str(), r.writers, r.commits, r.seconds, rate(r), r.p50_ms,
                    r.p99_ms, r.failed_writers, cpu);
    }
    for (const BenchRow& r : all_rows)
        if (r.failed_writers)
            std::printf("%s, %d writers: %d stopped, first: %s\n", r.backend.c_str(),
                        r.writers, r.failed_writers, r.first_error.c_str());
    // Ratios within this run: the server against the file at the same writer count.
    for (size_t i = 0; i + 1 < rows.size(); i += 2)
        if (rate(rows[i]) > 0)
            std::printf("writers %d: postgresql/sqlite throughput ratio %.2f\n",
                        rows[i].writers, rate(rows[i + 1]) / rate(rows[i]));
    // The serve rows: the same table, and each row against the store it writes into.
    for (size_t i = 0; i + 1 < serve_rows.size(); i += 2)
        for (size_t j = 0; j + 1 < rows.size(); j += 2)
            if (rows[j].writers == serve_rows[i].writers && rate(rows[j]) > 0 &&
                rate(rows[j + 1]) > 0)
                std::printf(
                    "writers %d: serve/sqlite throughput ratio %.2f, "
                    "serve/postgresql %.2f\n",
                    serve_rows[i].writers, rate(serve_rows[i]) / rate(rows[j]),
                    rate(serve_rows[i + 1]) / rate(rows[j + 1]));
    // Instances behind the proxy: throughput against one instance, same participants.
    for (const BenchRow& r : instance_rows)
        for (const BenchRow& one : instance_rows)
            if (r.instances > 1 && one.instances == 1 && one.writers == r.writers &&
                rate(one) > 0)
                std::printf("participants %d: %d instances / 1 throughput ratio %.2f\n",
                            r.writers, r.instances, rate(r) / rate(one));
    if (!csv.empty()) {
        std::ofstream out(csv);
        out << "backend,instances,writers,commits,seconds,commits_per_s,p50_ms,p99_ms,"
               "failed_writers,cpu_busy,cpu_self_share\n";
        for (const BenchRow& r : all_rows)
            out << '"' << r.backend << "\"," << r.instances << ',' << r.writers << ','
                << r.commits << ',' << r.seconds << ',' << rate(r) << ',' << r.p50_ms
                << ',' << r.p99_ms << ',' << r.failed_writers << ','
                << (r.cpu_busy >= 0 ? std::to_string(r.cpu_busy) : std::string()) << ','
                << (r.cpu_self >= 0 ? std::to_string(r.cpu_self) : std::string()) << "\n";
        if (!out) throw study::StoreError(csv + ": cannot write");
    }
    return kExitOk;
}

}  // namespace

void register_bench_store(CLI::App& bench, int& exit_code) {
    struct Args {
        std::vector<int> writers{1, 8, 50};
        std::vector<int> instances{1, 2, 4};
        std::vector<int> participants{1, 50, 300};
        int think_ms = 1000;
        int trials = 40;
        std::string server;
        std::string csv;
    };
    auto args = std::make_shared<Args>();
    auto* cmd = bench.add_subcommand(
        "store",
        "Trial commits per second and p50/p99 commit latency: SQLite file and PostgreSQL "
        "over a Unix socket (a throwaway local server unless --server), 1, 8 and 50 "
        "writers; lucent serve into each; 1, 2 and 4 serve instances behind nginx with "
        "1, 50 and 300 browsers");
    cmd->add_option("--writers", args->writers, "Concurrent writers per row")
        ->delimiter(',')
        ->capture_default_str();
    cmd->add_option("--instances", args->instances,
                    "Serve instances behind Debian's nginx, per group of rows")
        ->delimiter(',')
        ->check(CLI::Range(1, 16))
        ->capture_default_str();
    cmd->add_option("--participants", args->participants,
                    "Concurrent browsers through the proxy, per row")
        ->delimiter(',')
        ->check(CLI::Range(1, 1000))
        ->capture_default_str();
    cmd->add_option("--think-ms", args->think_ms,
                    "Milliseconds each browser behind the proxy waits before an answer "
                    "(a participant looking; real ones take seconds)")
        ->check(CLI::Range(0, 60000))
        ->capture_default_str();
    cmd->add_option("--trials", args->trials, "Trials each writer commits")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    cmd->add_option("--server", args->server,
                    "An initialised, empty postgresql:// server instead of a local one");
    cmd->add_option("--csv", args->csv, "Also write the table as CSV to this file");
    cmd->callback([args, &exit_code] {
        try {
            exit_code = run_bench_store(args->writers, args->trials, args->instances,
                                        args->participants, args->think_ms, args->server,
                                        args->csv);
        } catch (const study::StoreError& e) {
            std::cerr << "lucent bench store: " << e.what() << "\n";
            exit_code = kExitFailure;
        }
    });
}

}  // namespace lucent::app
