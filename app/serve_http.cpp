// lucent serve's HTTP layer (serve_http.h).
#include "app/serve_http.h"

#include <dirent.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdlib>
#include <list>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <thread>

#include "study/serve/web_files.h"
#include "study/session/stimulus_source.h"

namespace lucent::app {
namespace {

std::string one_line_json_error(const std::string& why) {
    std::string line = why;
    for (char& c : line)
        if (static_cast<unsigned char>(c) < 0x20) c = ' ';
    return nlohmann::json{{"error", line}}.dump(-1, ' ', false,
                                                nlohmann::json::error_handler_t::replace);
}

// ---- request deadlines --------------------------------------------------------------
// cpp-httplib 0.11 bounds each read of a request (read timeout) but not the request:
// a client sending a header line just within each timeout holds its worker for ever.
// So each connection a worker takes up gets a deadline, renewed by each reply written on
// it (the logger runs then, on that worker); a watchdog shuts the read side of a
// connection past its deadline, and the worker's pending read ends at once. A reply
// being written is not cut (the write side stays open; the write timeout bounds it).
//
// The library hands the pool only a closure, not the socket: the pool finds the socket
// just accepted (the listener thread enqueues right after accept) as the one connection
// to a listening port of this process it does not track yet, and keeps a dup of it, so
// the watchdog can never shut a later connection that reused the number.
struct Tracked {
    int fd = -1;  // our dup of the connection
    ino_t inode = 0;
    std::chrono::steady_clock::time_point deadline =
        std::chrono::steady_clock::time_point::max();
};

struct DeadlineState {
    std::chrono::milliseconds limit{5000};
    std::mutex mutex;
    std::list<Tracked> tracked;  // stable addresses
    std::condition_variable wake;
    bool stopping = false;
};

// The connection the current worker thread serves, when tracked.
thread_local Tracked* current_connection = nullptr;
thread_local DeadlineState* current_state = nullptr;

std::optional<int> local_port(int fd) {
    sockaddr_storage a{};
    socklen_t len = sizeof a;
    if (::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0)
        return std::nullopt;
    if (a.ss_family == AF_INET)
        return ntohs(reinterpret_cast<sockaddr_in*>(&a)->sin_port);
    if (a.ss_family == AF_INET6)
        return ntohs(reinterpret_cast<sockaddr_in6*>(&a)->sin6_port);
    return std::nullopt;
}

// The socket fds of this process: (fd, inode, listening).
struct SocketFd {
    int fd;
    ino_t inode;
    bool listening;
};
std::vector<SocketFd> socket_fds() {
    std::vector<SocketFd> out;
    DIR* dir = ::opendir("/proc/self/fd");
    if (!dir) return out;
    const int own = ::dirfd(dir);
    while (const dirent* e = ::readdir(dir)) {
        char* end = nullptr;
        const long fd = std::strtol(e->d_name, &end, 10);
        if (*end != '\0' || end == e->d_name || fd == own) continue;
        struct stat st {};
        if (::fstat(static_cast<int>(fd), &st) != 0 || !S_ISSOCK(st.st_mode)) continue;
        int accepting = 0;
        socklen_t len = sizeof accepting;
        if (::getsockopt(static_cast<int>(fd), SOL_SOCKET, SO_ACCEPTCONN, &accepting,
                         &len) != 0)
            continue;
        out.push_back({static_cast<int>(fd), st.st_ino, accepting != 0});
    }
    ::closedir(dir);
    return out;
}

class DeadlinePool : public httplib::ThreadPool {
public:
    DeadlinePool(size_t threads, std::chrono::milliseconds limit)
        : httplib::ThreadPool(threads), state_(std::make_shared<DeadlineState>()) {
        state_->limit = limit;
        watchdog_ = std::thread([state = state_] { watch(*state); });
    }
    ~DeadlinePool() override { stop_watchdog(); }

    void enqueue(std::function<void()> fn) override {
        Tracked* entry = track_newest();
        if (!entry) return httplib::ThreadPool::enqueue(std::move(fn));
        httplib::ThreadPool::enqueue([fn = std::move(fn), entry, state = state_] {
            {
                std::lock_guard lock(state->mutex);
                entry->deadline = std::chrono::steady_clock::now() + state->limit;
            }
            current_connection = entry;
            current_state = state.get();
            fn();
            current_connection = nullptr;
            current_state = nullptr;
            std::lock_guard lock(state->mutex);
            ::close(entry->fd);
            state->tracked.remove_if([entry](const Tracked& t) { return &t == entry; });
        });
    }
    void shutdown() override {
        httplib::ThreadPool::shutdown();
        stop_watchdog();
    }

    // After a reply on the current worker's connection: the next request's deadline.
    static void renew() {
        if (!current_connection || !current_state) return;
        std::lock_guard lock(current_state->mutex);
        current_connection->deadline =
            std::chrono::steady_clock::now() + current_state->limit;
    }

private:
    Tracked* track_newest() {
        const std::vector<SocketFd> fds = socket_fds();
        std::set<int> ports;
        for (const SocketFd& s : fds)
            if (s.listening)
                if (const auto port = local_port(s.fd)) ports.insert(*port);
        std::lock_guard lock(state_->mutex);
        std::set<ino_t> known;
        for (const Tracked& t : state_->tracked) known.insert(t.inode);
        const SocketFd* found = nullptr;
        for (const SocketFd& s : fds) {
            if (s.listening || known.count(s.inode)) continue;
            const auto port = local_port(s.fd);
            if (!port || !ports.count(*port)) continue;
            if (found) return nullptr;  // not one new connection: leave it unwatched
            found = &s;
        }
        if (!found) return nullptr;
        const int copy = ::fcntl(found->fd, F_DUPFD_CLOEXEC, 0);
        if (copy < 0) return nullptr;
        state_->tracked.push_back({copy, found->inode});
        return &state_->tracked.back();
    }

    static void watch(DeadlineState& state) {
        std::unique_lock lock(state.mutex);
        const auto tick = std::clamp(state.limit / 10, std::chrono::milliseconds(10),
                                     std::chrono::milliseconds(500));
        while (!state.stopping) {
            state.wake.wait_for(lock, tick);
            const auto now = std::chrono::steady_clock::now();
            for (Tracked& t : state.tracked)
                if (t.deadline <= now) {
                    ::shutdown(t.fd, SHUT_RD);  // the worker's read returns at once
                    t.deadline = std::chrono::steady_clock::time_point::max();
                }
        }
    }

    void stop_watchdog() {
        {
            std::lock_guard lock(state_->mutex);
            state_->stopping = true;
        }
        state_->wake.notify_all();
        if (watchdog_.joinable()) watchdog_.join();
    }

    std::shared_ptr<DeadlineState> state_;
    std::thread watchdog_;
};

}  // namespace

void configure_serve_http(httplib::Server& http, study::WebStudy& web,
                          const std::map<std::string, ServedPicture>& pictures,
                          const ServeHttpLimits& limits) {
    const size_t threads = static_cast<size_t>(std::max(1, limits.threads));
    const std::chrono::milliseconds deadline = limits.request_deadline;
    http.new_task_queue = [threads, deadline] {
        return new DeadlinePool(threads, deadline);
    };
    http.set_logger(
        [](const httplib::Request&, const httplib::Response&) { DeadlinePool::renew(); });
    http.set_tcp_nodelay(true);  // each reply at once: no Nagle wait for a delayed ACK
    http.set_payload_max_length(64 * 1024);  // larger bodies: 413 before they are read
    http.set_read_timeout(limits.read_timeout);
    http.set_write_timeout(10);
    http.set_keep_alive_timeout(2);
    http.set_default_headers(
        {{"X-Content-Type-Options", "nosniff"},
         {"Referrer-Policy", "no-referrer"},
         {"X-Frame-Options", "DENY"},
         {"Content-Security-Policy",
          "default-src 'self'; img-src 'self'; frame-ancestors 'none'"},
         {"Cache-Control", "no-store"}});
    auto page_file = [](const char* name, const char* type) {
        return [name, type](const httplib::Request&, httplib::Response& res) {
            res.set_content(std::string(*embedded::serve_file(name)), type);
        };
    };
    http.Get("/", page_file("index.html", "text/html; charset=utf-8"));
    http.Get("/lucent.js", page_file("lucent.js", "text/javascript; charset=utf-8"));
    http.Get("/lucent.css", page_file("lucent.css", "text/css; charset=utf-8"));
    http.Get(R"(/images/.*)", [&web, &pictures](const httplib::Request& req,
                                                httplib::Response& res) {
        // Matched on the raw target: only a name this study gave is a picture.
        const std::optional<study::NamedPicture> named = web.picture(req.target);
        if (!named) {
            res.status = 404;
            res.set_content(one_line_json_error("no such picture: " + req.target),
                            "application/json");
            return;
        }
        // This serving's bytes: the picture with its own one-step noise, so no two
        // servings hash alike (picture_names.h).
        study::CpuImage image =
            study::decode_png_rgba8(pictures.at(named->id).png, named->id);
        study::add_serving_noise(image.rgba, named->noise_seed);
        res.set_header("Cache-Control", "private, max-age=3600");
        res.set_content(study::encode_png_rgba8(image), "image/png");
    });
    http.Post(
        R"(/api/([a-z_]+))", [&web](const httplib::Request& req, httplib::Response& res) {
            const study::WebReply reply = web.handle(req.matches[1].str(), req.body);
            res.status = reply.status;
            if (reply.retry_after_s > 0)
                res.set_header("Retry-After", std::to_string(reply.retry_after_s));
            res.set_content(reply.body, "application/json");
        });
    // For the proxy's and the operator's health checks: 200 only when the store answers.
    http.Get("/healthz", [&web](const httplib::Request&, httplib::Response& res) {
        const study::WebReply reply = web.health();
        res.status = reply.status;
        if (reply.retry_after_s > 0)
            res.set_header("Retry-After", std::to_string(reply.retry_after_s));
        res.set_content(reply.body, "application/json");
    });
    http.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
        if (!res.body.empty()) return;
        const std::string why = res.status == 413 ? "request body over 65536 bytes"
                                : res.status == 404
                                    ? "not found: " + req.method + " " + req.target
                                    : "HTTP " + std::to_string(res.status);
        res.set_content(one_line_json_error(why), "application/json");
    });
    http.set_exception_handler(
        [](const httplib::Request&, httplib::Response& res, std::exception_ptr) {
            res.status = 500;
            res.set_content(one_line_json_error("internal error"), "application/json");
        });
}

int bind_serve_port(httplib::Server& http, const std::string& host, int port) {
    // The library listens with a backlog of 5 (compiled in), which drops connections
    // when many participants arrive at once: the socket is kept and listened on again
    // with a deeper queue (Linux takes a second listen() as a new backlog).
    int listen_fd = -1;
    http.set_socket_options([&listen_fd](socket_t fd) {
        int yes = 1;
        ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
        listen_fd = fd;
    });
    if (port == 0) {
        port = http.bind_to_any_port(host);
    } else if (!http.bind_to_port(host, port)) {
        port = -1;
    }
    if (port >= 0 && listen_fd >= 0) ::listen(listen_fd, 1024);
    return port;
}

}  // namespace lucent::app
