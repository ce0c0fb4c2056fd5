#pragma once
// Debian's nginx as a round-robin reverse proxy in front of several HTTP servers on
// loopback, for `lucent bench store`'s rows of several serve instances and the tests of
// `lucent serve` run as several instances: /usr/sbin/nginx
// started as a child process (master and one worker, not daemonised) with a config of
// its own in a fresh temporary prefix folder (pid file, error log, temp paths all in
// there), listening on 127.0.0.1 on a free port. Nothing of a system nginx is used or
// touched (its config, its logs, /var/lib/nginx, port 80).
//
// The config is the deployment's (docs/deploy.md) without TLS and with a 1m body limit
// (not 64k): upstreams with max_fails=1 (Options::max_fails) fail_timeout=2s and
// keepalive, proxy_next_upstream on errors, timeouts, 502 and 503. One location of its
// own, /.nginx-proxy-generation, answers which config is active; the harness polls it to
// know that nginx is up and that a reload took.
#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace lucent::app {

struct NginxProxyOptions {
    // proxy_next_upstream with `non_idempotent`: POST requests are retried on another
    // upstream too (lucent's API is idempotent by design: the same answer twice is
    // stored once).
    bool retry_non_idempotent = true;
    // Each upstream's max_fails (fail_timeout 2s): 1, the deployment's, takes an upstream
    // that failed out of the rotation for 2 s; 0 never does, so a dead upstream is
    // met again by every other request (nginx passing each on to the next one), which a
    // test can rely on without waiting out a timeout.
    int max_fails = 1;
};

class NginxProxy {
public:
    using Options = NginxProxyOptions;
    static constexpr const char* kBinary = "/usr/sbin/nginx";

    // Whether Debian's nginx is installed (package nginx; scripts/install-deps).
    static bool available();

    // Starts nginx over `upstream_ports` (on 127.0.0.1; at least one). Throws
    // std::runtime_error with a one-line reason (the error log's last line) when it does
    // not serve within 5 s. The child is sent SIGTERM when the thread that constructed
    // it ends (PR_SET_PDEATHSIG), so a crashed test leaves no nginx behind.
    explicit NginxProxy(std::vector<int> upstream_ports, Options options = {});
    // Fast shutdown (SIGTERM; SIGKILL to its process group after 3 s), then removes the
    // prefix folder.
    ~NginxProxy();
    NginxProxy(const NginxProxy&) = delete;
    NginxProxy& operator=(const NginxProxy&) = delete;

    int port() const { return port_; }
    std::string url() const { return "http://127.0.0.1:" + std::to_string(port_); }
    const std::filesystem::path& prefix() const { return prefix_; }
    std::filesystem::path config_path() const { return prefix_ / "nginx.conf"; }
    std::filesystem::path error_log_path() const { return prefix_ / "error.log"; }
    // Whether the master process is still running.
    bool running();

    // Rewrites the config over `upstream_ports` and reloads it (SIGHUP to the master);
    // returns once every new connection is served by the new config: the new config
    // answers and the old workers have exited (or, still finishing requests after 5 s,
    // no longer accept). Throws std::runtime_error when nginx rejects the config (it
    // keeps the old one then; the reason is the error log's [emerg] line) or when the
    // new config is not active within 5 s.
    void reload(std::vector<int> upstream_ports);

private:
    enum class Start { ok, port_taken, failed };
    Start start_once(std::string& reason);
    void write_config() const;
    bool wait_for_generation(int generation, int timeout_ms, std::string& reason);
    void kill_master();
    std::string last_log_line() const;

    Options options_;
    std::vector<int> upstreams_;
    std::filesystem::path prefix_;
    pid_t pid_ = -1;
    int port_ = 0;
    int generation_ = 0;
};

}  // namespace lucent::app
