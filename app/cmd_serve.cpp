// lucent serve: the study for online participants in a browser. The HTTP layer only:
// every decision is in study/serve/web_study.h; the page is embedded (serve/web/).
#include <fcntl.h>
#include <httplib.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>

#include "app/analysis_plan.h"
#include "app/commands.h"
#include "app/serve_http.h"
#include "lucent/version.h"
#include "study/postgres/trial_journal.h"
#include "study/protocol.h"
#include "study/serve/web_study.h"
#include "study/session/session_flow.h"
#include "study/session/stimulus_source.h"
#include "study/sqlite/sqlite_store.h"
#include "study/store_pool.h"
#include "study/study_store.h"
#include "study/trial_plan.h"
#include "study/web_series.h"

namespace lucent::app {
namespace {

struct ServeArgs {
    std::string protocol_file;
    std::string preset;
    std::string images_dir;
    std::string db;
    std::string listen = "127.0.0.1:8080";
    std::string secret_file;
    int threads = 64;
    int store_connections = 4;
    int store_wait_ms = 2000;
    double idle_minutes = 30;
    double request_timeout_s = 5;
};

std::string read_file(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

// Every stimulus's picture as the lab shows it (load_image_rgba8: 8-bit sRGB, EXR
// encoded on the way), kept in memory as PNG: nothing else on disk is ever served. Each
// serving decodes it and adds its own noise (picture_names.h).
std::map<std::string, ServedPicture> load_pictures(
    const study::Protocol& protocol, const study::PrerenderedStimuli& stimuli) {
    std::map<std::string, ServedPicture> out;
    for (const Stimulus& s : protocol.stimuli) {
        const study::CpuImage image = study::load_image_rgba8(stimuli.path_for(s));
        out[s.id] = {study::encode_png_rgba8(image), {image.width, image.height}};
    }
    return out;
}

// The key of the session tokens, kept in a file so tokens survive a restart and every
// instance of a study checks every other's (docs/deploy.md). Refused: a file others may
// read (anyone who reads it can sign any participant's token) and a key with too little
// entropy (shorter than 32 bytes, or fewer than 8 distinct byte values: all one byte, a
// short pattern repeated; a hex or base64 text of 32 random bytes passes). Created (32
// bytes of /dev/urandom, mode 0600, said on stderr) only where that cannot split a
// study: beside an SQLite file, which one machine serves.
std::string load_or_create_secret(const std::string& path, bool may_create) {
    struct stat info {};
    if (::stat(path.c_str(), &info) == 0) {
        if ((info.st_mode & 077) != 0) {
            char mode[8];
            std::snprintf(mode, sizeof mode, "%04o", unsigned(info.st_mode & 07777));
            throw std::runtime_error(path +
                                     ": the session key file may be read by group "
                                     "or others (mode " +
                                     mode + "); chmod 600 " + path);
        }
        const std::string secret = read_file(path);
        if (secret.size() < 32)
            throw std::runtime_error(path + ": session key of " +
                                     std::to_string(secret.size()) +
                                     " bytes is shorter than 32 bytes (head -c 32 "
                                     "/dev/urandom > KEY)");
        const std::set<char> distinct(secret.begin(), secret.end());
        if (distinct.size() < 8)
            throw std::runtime_error(
                path + ": session key has too little entropy (" +
                std::to_string(distinct.size()) + " distinct byte values in " +
                std::to_string(secret.size()) +
                " bytes); make it with head -c 32 /dev/urandom > KEY");
        return secret;
    }
    if (!may_create)
        throw std::runtime_error(path +
                                 ": no such session key file (make it once with "
                                 "head -c 32 /dev/urandom, mode 0600, and give "
                                 "every instance the same file)");
    std::filesystem::create_directories(std::filesystem::absolute(path).parent_path());
    std::string secret(32, '\0');
    std::ifstream random("/dev/urandom", std::ios::binary);
    random.read(secret.data(), static_cast<std::streamsize>(secret.size()));
    if (random.gcount() != 32) throw std::runtime_error("cannot read /dev/urandom");
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd < 0)
        throw std::runtime_error(
            path + ": cannot create the session key file: " + std::strerror(errno));
    const bool written = ::write(fd, secret.data(), secret.size()) ==
                             static_cast<ssize_t>(secret.size()) &&
                         ::fsync(fd) == 0;
    ::close(fd);
    if (!written) throw std::runtime_error(path + ": cannot write the session key file");
    std::cerr << "lucent serve: created the session key " << path
              << " (32 random bytes, mode 0600)" << std::endl;
    return secret;
}

bool parse_listen(const std::string& listen, std::string& host, int& port) {
    const size_t colon = listen.rfind(':');
    if (colon == std::string::npos || colon == 0) return false;
    host = listen.substr(0, colon);
    if (host.size() > 2 && host.front() == '[' && host.back() == ']')
        host = host.substr(1, host.size() - 2);
    const std::string digits = listen.substr(colon + 1);
    if (digits.empty() || digits.size() > 5 ||
        digits.find_first_not_of("0123456789") != std::string::npos)
        return false;
    port = std::stoi(digits);
    return port <= 65535;
}

bool is_loopback(const std::string& host) {
    return host == "localhost" || host == "::1" || host.rfind("127.", 0) == 0;
}

int serve_command(const ServeArgs& args) {
    if (args.protocol_file.empty() == args.preset.empty()) {
        std::cerr
            << "lucent serve: give a PROTOCOL.toml or --preset NAME (exactly one)\n";
        return kExitUsage;
    }
    std::string host;
    int port = 0;
    if (!parse_listen(args.listen, host, port)) {
        std::cerr << "lucent serve: --listen '" << args.listen
                  << "': expected HOST:PORT, e.g. 127.0.0.1:8080\n";
        return kExitUsage;
    }
    // A server store is shared by instances: each must be given the study's one key, or
    // every page another instance started would be refused by this one (403).
    const bool server = study::is_server_uri(args.db);
    if (server && args.secret_file.empty()) {
        std::cerr << "lucent serve: --db " << args.db
                  << ": a server store needs --secret-file KEY, the one key file every "
                     "instance of the study shares (docs/deploy.md)\n";
        return kExitUsage;
    }
    std::string key_line;
    study::Protocol protocol;
    std::unique_ptr<study::StorePool> stores;
    std::unique_ptr<study::WebStudy> web;
    std::map<std::string, ServedPicture> pictures;
    try {
        protocol = args.preset.empty() ? study::load_protocol_file(args.protocol_file)
                                       : study::builtin_protocol(args.preset);
        check_analysis_plan(protocol);       // a plan naming no analysis fails here
        study::plan_trials(protocol, 0, 0);  // impossible randomisation fails here, early
        // The adjust series and staircase ladders are pictures of their own, each
        // checked against the manifest like the protocol's stimuli.
        study::WebSeries series = study::web_series(protocol);
        const study::Protocol shown = study::with_series_pictures(protocol, series);
        const study::PrerenderedStimuli stimuli(args.images_dir);
        stimuli.check(shown);
        study::WebStudyOptions options;
        options.environment.machine_id = study::machine_id();
        options.environment.software_version = version_string();
        options.environment.build_hash = build_hash();
        // Each segment records the protocol's stimuli, and names the set of series
        // pictures it serves (each picture's file and content hash, once per set).
        options.environment.stimuli = stimuli.provenance(shown);
        options.environment.series_pictures.assign(
            options.environment.stimuli.begin() +
                static_cast<std::ptrdiff_t>(protocol.stimuli.size()),
            options.environment.stimuli.end());
        options.environment.stimuli.resize(protocol.stimuli.size());
        options.series = std::move(series);
        pictures = load_pictures(shown, stimuli);
        for (const auto& [id, picture] : pictures) options.images[id] = picture.size;
        const std::string secret_file =
            !args.secret_file.empty() ? args.secret_file : args.db + "-serve-key";
        options.secret = load_or_create_secret(secret_file, !server);
        key_line = "lucent serve: session key " + secret_file + ", fingerprint " +
                   study::key_fingerprint(options.secret) +
                   " (the same on every instance of the study: /healthz)";
        options.idle_timeout = std::chrono::milliseconds(
            static_cast<int64_t>(std::llround(args.idle_minutes * 60'000)));
        // No local journal: an answer is acknowledged only once the study's database
        // committed it (study/serve/README.md).
        study::StoreOptions store_options;
        store_options.journal = false;
        // An SQLite file takes one writer at a time anyway: one connection (several
        // gain nothing there, and are not yet tested to see each other's commits).
        const size_t connections = study::is_server_uri(args.db)
                                       ? static_cast<size_t>(args.store_connections)
                                       : 1;
        stores = std::make_unique<study::StorePool>(
            args.db, connections, store_options,
            std::chrono::milliseconds(args.store_wait_ms));
        web = std::make_unique<study::WebStudy>(protocol, *stores, options);
    } catch (const study::ProtocolError& e) {
        std::cerr << "lucent serve: " << e.what() << "\n";
        return kExitUsage;
    } catch (const study::PlanError& e) {
        std::cerr << "lucent serve: " << e.what() << "\n";
        return kExitUsage;
    } catch (const study::StimulusError& e) {
        std::cerr << "lucent serve: " << e.what() << "\n";
        return kExitUsage;
    } catch (const study::StoreError& e) {
        std::cerr << "lucent serve: " << e.what() << "\n";
        return kExitUsage;
    } catch (const std::exception& e) {
        std::cerr << "lucent serve: " << e.what() << "\n";
        return kExitFailure;
    }

    httplib::Server http;
    ServeHttpLimits limits;
    limits.threads = args.threads;
    limits.request_deadline = std::chrono::milliseconds(
        static_cast<int64_t>(std::llround(args.request_timeout_s * 1000)));
    limits.read_timeout = limits.request_deadline;
    configure_serve_http(http, *web, pictures, limits);
    port = bind_serve_port(http, host, port);
    if (port < 0) {
        std::cerr << "lucent serve: cannot listen on " << args.listen << ": "
                  << std::strerror(errno) << "\n";
        return kExitFailure;
    }
    // SIGINT/SIGTERM stop the server from a thread of their own (never in a handler).
    sigset_t stop_signals;
    sigemptyset(&stop_signals);
    sigaddset(&stop_signals, SIGINT);
    sigaddset(&stop_signals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
    std::atomic<bool> listen_over{false};
    std::thread stopper([&] {
        int signal = 0;
        sigwait(&stop_signals, &signal);
        // A signal right after the first line may come before the server runs, when
        // stop() does nothing: wait until it runs (or never will).
        while (!http.is_running() && !listen_over)
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        http.stop();
    });
    std::cout << "lucent serve: study '" << protocol.name << "' (" << pictures.size()
              << " pictures) from " << stores->name() << " (" << stores->size()
              << " connections) on http://"
              << (host.find(':') != std::string::npos ? "[" + host + "]" : host) << ":"
              << port << "/?participant=ID" << std::endl;
    std::cout << key_line << std::endl;
    if (!is_loopback(host))
        std::cout << "lucent serve: note: listening beyond this machine (" << host
                  << "); serve participants through an HTTPS reverse proxy "
                     "(docs/run-and-serve.md)"
                  << std::endl;
    http.listen_after_bind();
    listen_over = true;
    if (stopper.joinable()) {
        pthread_kill(stopper.native_handle(),
                     SIGTERM);  // wakes sigwait when stopped otherwise
        stopper.join();
    }
    std::cout << "lucent serve: stopped (every answer acknowledged is in "
              << stores->name() << "; open pages go on with another instance or after "
              << "a restart)" << std::endl;
    return kExitOk;
}

}  // namespace

void register_serve(CLI::App& app, int& exit_code) {
    auto args = std::make_shared<ServeArgs>();
    auto* cmd = app.add_subcommand(
        "serve",
        "Serve the study to online participants in a browser (same protocol as 'run')");
    cmd->add_option("protocol", args->protocol_file, "Study protocol file (TOML)");
    cmd->add_option("--preset", args->preset, "Built-in protocol instead of a file")
        ->check(CLI::IsMember(study::builtin_protocol_names()));
    cmd->add_option(
        "--images", args->images_dir,
        "Directory of pre-rendered images named <stimulus id>.png|.tif|.exr (e.g. from "
        "'lucent render --preset thesis --out DIR')");
    cmd->add_option("--db", args->db,
                    "Study database: FILE.db or postgresql://USER@HOST[:PORT]/DBNAME")
        ->required();
    cmd->add_option("--listen", args->listen,
                    "HOST:PORT to listen on (default 127.0.0.1:8080, loopback only; port "
                    "0 picks one)");
    cmd->add_option(
        "--secret-file", args->secret_file,
        "Key of the participants' session tokens, at least 32 random bytes, mode "
        "0600: required with a server store (every instance gives the same file); "
        "default beside an SQLite file, DB-serve-key, created when absent");
    cmd->add_option("--threads", args->threads,
                    "HTTP worker threads (connections served at once)")
        ->check(CLI::Range(2, 1024));
    cmd->add_option("--store-connections", args->store_connections,
                    "Store connections this process keeps (default 4); requests beyond "
                    "them wait --store-wait-ms")
        ->check(CLI::Range(1, 256));
    cmd->add_option("--store-wait-ms", args->store_wait_ms,
                    "How long a request waits for a free store connection before it "
                    "is answered 503 with Retry-After (default 2000)")
        ->check(CLI::Range(1, 600'000));
    cmd->add_option(
           "--idle-minutes", args->idle_minutes,
           "A session with no activity this long no longer holds its counterbalancing "
           "cell: the next arrival may take it (it still resumes; default 30)")
        ->check(CLI::Range(0.001, 1e6));
    cmd->add_option("--request-timeout", args->request_timeout_s,
                    "Seconds a request may take to arrive; slower connections are cut "
                    "(default 5)")
        ->check(CLI::Range(0.05, 600.0));
    cmd->callback([args, &exit_code] { exit_code = serve_command(*args); });
}

}  // namespace lucent::app
