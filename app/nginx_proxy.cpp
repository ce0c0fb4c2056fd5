#include "app/nginx_proxy.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <thread>

namespace lucent::app {

namespace {

constexpr int kStartTimeoutMs = 5000;
constexpr int kReloadTimeoutMs = 5000;
constexpr int kStopTimeoutMs = 3000;
constexpr int kPortAttempts = 5;
constexpr const char* kGenerationPath = "/.nginx-proxy-generation";

// A port the kernel had free on 127.0.0.1 a moment ago (bound to 0, read back, closed).
// Another process may take it before nginx binds it; the caller retries then.
int free_loopback_port() {
    const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) return 0;
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = 0;
    socklen_t length = sizeof(addr);
    int port = 0;
    if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0 &&
        getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &length) == 0)
        port = ntohs(addr.sin_port);
    close(fd);
    return port;
}

// The whole reply to one HTTP/1.0 GET on 127.0.0.1:port (empty when nothing answered).
std::string http_get(int port, const std::string& path) {
    const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) return {};
    timeval timeout{0, 500 * 1000};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
    setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof(timeout));
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = htons(static_cast<uint16_t>(port));
    std::string reply;
    if (connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) == 0) {
        const std::string request =
            "GET " + path + " HTTP/1.0\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
        if (send(fd, request.data(), request.size(), MSG_NOSIGNAL) ==
            static_cast<ssize_t>(request.size())) {
            char buffer[4096];
            ssize_t n = 0;
            while ((n = recv(fd, buffer, sizeof(buffer), 0)) > 0) reply.append(buffer, n);
        }
    }
    close(fd);
    return reply;
}

// The processes whose parent is `parent` (from /proc/PID/stat: "PID (NAME) STATE PPID").
std::vector<pid_t> children_of(pid_t parent) {
    std::vector<pid_t> children;
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator("/proc", error)) {
        const std::string name = entry.path().filename().string();
        if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos)
            continue;
        std::ifstream in(entry.path() / "stat");
        std::string stat;
        std::getline(in, stat);
        const size_t end = stat.rfind(')');
        if (end == std::string::npos) continue;
        std::istringstream fields(stat.substr(end + 1));
        std::string state;
        pid_t ppid = 0;
        if (fields >> state >> ppid && ppid == parent)
            children.push_back(std::stoi(name));
    }
    return children;
}

std::string read_file(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

std::string last_line(const std::string& text) {
    size_t end = text.find_last_not_of("\r\n");
    if (end == std::string::npos) return {};
    const size_t begin = text.rfind('\n', end);
    return text.substr(begin == std::string::npos ? 0 : begin + 1,
                       end + 1 - (begin == std::string::npos ? 0 : begin + 1));
}

// nginx reports a port taken as "bind() to 127.0.0.1:N failed (98: Address already in
// use)" and then retries for 2.5 s; the harness takes another port at once instead.
bool port_taken(const std::string& log) {
    return log.find("(98: Address already in use)") != std::string::npos;
}

}  // namespace

bool NginxProxy::available() { return access(kBinary, X_OK) == 0; }

NginxProxy::NginxProxy(std::vector<int> upstream_ports, Options options)
    : options_(options), upstreams_(std::move(upstream_ports)) {
    if (upstreams_.empty())
        throw std::invalid_argument("NginxProxy: no upstream ports given");
    if (!available())
        throw std::runtime_error(
            std::string("NginxProxy: ") + kBinary +
            " not found (Debian package nginx; scripts/install-deps)");
    std::string folder =
        (std::filesystem::temp_directory_path() / "lucent-nginx-XXXXXX").string();
    if (!mkdtemp(folder.data()))
        throw std::runtime_error("NginxProxy: cannot create a prefix folder in " +
                                 std::filesystem::temp_directory_path().string() + ": " +
                                 std::strerror(errno));
    prefix_ = folder;
    std::string reason = "no free port on 127.0.0.1";
    for (int attempt = 0; attempt < kPortAttempts; ++attempt) {
        port_ = free_loopback_port();
        if (port_ == 0) continue;
        const Start result = start_once(reason);
        if (result == Start::ok) return;
        if (result == Start::failed) break;
    }
    std::error_code ignored;
    std::filesystem::remove_all(prefix_, ignored);
    throw std::runtime_error("NginxProxy: nginx did not start: " + reason);
}

NginxProxy::~NginxProxy() {
    kill_master();
    std::error_code ignored;
    if (!prefix_.empty()) std::filesystem::remove_all(prefix_, ignored);
}

bool NginxProxy::running() {
    if (pid_ <= 0) return false;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return false;
    }
    return true;
}

void NginxProxy::write_config() const {
    const std::string p = prefix_.string();
    std::ostringstream c;
    c << "# Written by lucent (app/nginx_proxy.cpp) (generation " << generation_
      << "); every path is in this prefix.\n"
      << "daemon off;\n"
      << "master_process on;\n"
      << "worker_processes 1;\n"
      << "pid \"" << p << "/nginx.pid\";\n"
      << "lock_file \"" << p << "/nginx.lock\";\n"
      << "error_log \"" << p << "/error.log\" warn;\n";
    // As root, workers would otherwise run as nobody (Debian's build names no user).
    if (geteuid() == 0) c << "user root;\n";
    c << "events { worker_connections 4096; }\n"
      << "http {\n"
      << "    access_log off;\n"
      << "    client_body_temp_path \"" << p << "/client_body\";\n"
      << "    proxy_temp_path \"" << p << "/proxy\";\n"
      << "    fastcgi_temp_path \"" << p << "/fastcgi\";\n"
      << "    uwsgi_temp_path \"" << p << "/uwsgi\";\n"
      << "    scgi_temp_path \"" << p << "/scgi\";\n"
      << "    client_max_body_size 1m;\n"
      << "    upstream lucent_instances {\n";
    for (int upstream : upstreams_)
        c << "        server 127.0.0.1:" << upstream
          << " max_fails=" << options_.max_fails << " fail_timeout=2s;\n";
    c << "        keepalive 16;\n"
      << "    }\n"
      << "    server {\n"
      << "        listen 127.0.0.1:" << port_ << ";\n"
      << "        location = " << kGenerationPath << " {\n"
      << "            default_type text/plain;\n"
      << "            return 200 \"" << p << " " << generation_ << "\\n\";\n"
      << "        }\n"
      << "        location / {\n"
      << "            proxy_pass http://lucent_instances;\n"
      << "            proxy_http_version 1.1;\n"
      << "            proxy_set_header Connection \"\";\n"
      << "            proxy_set_header Host $host;\n"
      << "            proxy_set_header X-Forwarded-For $proxy_add_x_forwarded_for;\n"
      << "            proxy_connect_timeout 1s;\n"
      << "            proxy_read_timeout 30s;\n"
      << "            proxy_next_upstream error timeout http_502 http_503"
      << (options_.retry_non_idempotent ? " non_idempotent" : "") << ";\n"
      << "            proxy_next_upstream_tries 3;\n"
      << "        }\n"
      << "    }\n"
      << "}\n";
    const std::filesystem::path staged = prefix_ / "nginx.conf.new";
    std::ofstream(staged) << c.str();
    std::filesystem::rename(staged, config_path());
}

NginxProxy::Start NginxProxy::start_once(std::string& reason) {
    write_config();
    std::error_code ignored;
    std::filesystem::remove(error_log_path(), ignored);
    const std::string prefix = prefix_.string() + "/";
    const std::string config = config_path().string();
    const std::string error_log = error_log_path().string();
    const std::string output = (prefix_ / "stderr.log").string();
    const pid_t parent = getpid();
    pid_ = fork();
    if (pid_ < 0) {
        reason = std::string("fork: ") + std::strerror(errno);
        return Start::failed;
    }
    if (pid_ == 0) {
        // Its own process group (so a stuck master and its worker go together), SIGTERM
        // when the test dies, no descriptor of the test's (an upstream's listening socket
        // held open by nginx would keep a stopped upstream accepting).
        setpgid(0, 0);
        prctl(PR_SET_PDEATHSIG, SIGTERM);
        if (getppid() != parent) _exit(126);
        const int null = open("/dev/null", O_RDONLY);
        const int out = open(output.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
        dup2(null, 0);
        dup2(out, 1);
        dup2(out, 2);
        syscall(SYS_close_range, 3U, ~0U, 0U);
        const char* argv[] = {kBinary,        "-p", prefix.c_str(),    "-c",
                              config.c_str(), "-e", error_log.c_str(), nullptr};
        execv(kBinary, const_cast<char* const*>(argv));
        _exit(127);
    }
    setpgid(pid_, pid_);
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(kStartTimeoutMs);
    while (std::chrono::steady_clock::now() < deadline) {
        std::string unused;
        if (wait_for_generation(generation_, 0, unused)) return Start::ok;
        const std::string log = read_file(error_log_path());
        if (!running()) {
            reason = "nginx exited: " + last_log_line();
            return port_taken(log) ? Start::port_taken : Start::failed;
        }
        if (port_taken(log)) {
            kill_master();
            reason = "port " + std::to_string(port_) + " taken: " + last_line(log);
            return Start::port_taken;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    reason = "no answer on 127.0.0.1:" + std::to_string(port_) + " within " +
             std::to_string(kStartTimeoutMs / 1000) + " s: " + last_log_line();
    kill_master();
    return Start::failed;
}

bool NginxProxy::wait_for_generation(int generation, int timeout_ms,
                                     std::string& reason) {
    const std::string expected =
        prefix_.string() + " " + std::to_string(generation) + "\n";
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    while (true) {
        const std::string reply = http_get(port_, kGenerationPath);
        const size_t body = reply.find("\r\n\r\n");
        if (reply.rfind("HTTP/1.1 200", 0) == 0 && body != std::string::npos &&
            reply.substr(body + 4) == expected)
            return true;
        if (std::chrono::steady_clock::now() >= deadline) {
            reason = reply.empty() ? "no answer on 127.0.0.1:" + std::to_string(port_)
                                   : "still serving an older config";
            return false;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
}

void NginxProxy::reload(std::vector<int> upstream_ports) {
    if (upstream_ports.empty())
        throw std::invalid_argument("NginxProxy::reload: no upstream ports given");
    if (!running())
        throw std::runtime_error("NginxProxy::reload: nginx is not running: " +
                                 last_log_line());
    upstreams_ = std::move(upstream_ports);
    ++generation_;
    write_config();
    const size_t log_before = read_file(error_log_path()).size();
    const std::vector<pid_t> old_workers = children_of(pid_);
    kill(pid_, SIGHUP);
    // The master starts workers on the new config, then tells the old ones to quit
    // gracefully; until an old worker has closed its listening socket it still accepts
    // connections on the old config. So: the new config answers, and no old worker is
    // left (one still running at the deadline has closed its listener and is finishing
    // requests). A config nginx rejects shows as an [emerg] line; it keeps the old one.
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(kReloadTimeoutMs);
    bool active = false;
    std::string reason;
    while (true) {
        active = active || wait_for_generation(generation_, 0, reason);
        bool old_left = false;
        for (pid_t child : children_of(pid_))
            for (pid_t old : old_workers) old_left = old_left || child == old;
        if (active && !old_left) break;
        const std::string log = read_file(error_log_path());
        if (!active && log.size() > log_before &&
            log.find("[emerg]", log_before) != std::string::npos) {
            reason = "rejected";
            break;
        }
        if (!running() || std::chrono::steady_clock::now() >= deadline) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (!running())
        throw std::runtime_error("NginxProxy::reload: nginx exited: " + last_log_line());
    if (!active)
        throw std::runtime_error("NginxProxy::reload: the new config is not active (" +
                                 reason + "): " + last_log_line());
}

void NginxProxy::kill_master() {
    if (pid_ <= 0) return;
    // SIGTERM: fast shutdown (open connections are closed, not drained).
    kill(pid_, SIGTERM);
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(kStopTimeoutMs);
    int status = 0;
    while (std::chrono::steady_clock::now() < deadline) {
        if (waitpid(pid_, &status, WNOHANG) == pid_) {
            pid_ = -1;
            return;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    // Not yet reaped, so its process group is still its own.
    kill(-pid_, SIGKILL);
    waitpid(pid_, &status, 0);
    pid_ = -1;
}

std::string NginxProxy::last_log_line() const {
    std::string line = last_line(read_file(error_log_path()));
    if (line.empty()) line = last_line(read_file(prefix_ / "stderr.log"));
    return line.empty() ? "(nothing in its error log)" : line;
}

}  // namespace lucent::app
