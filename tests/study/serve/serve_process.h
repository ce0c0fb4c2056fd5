#pragma once
// The real `lucent serve` for tests: a study folder (protocol + pictures of known
// colours), the server started on a free loopback port (--listen 127.0.0.1:0, the port
// read from its first line) and stopped with SIGTERM.
#include <OpenImageIO/imageio.h>
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "tests/study/serve/web_page.h"

namespace lucent::test {

// Four pictures of one colour each (64 x 48), a practice trial, a catch trial and a
// 5-point second question; breaks after every 2 main trials.
inline std::string write_serve_study(const std::filesystem::path& dir) {
    const struct {
        const char* id;
        unsigned char rgb[3];
    } pictures[] = {{"a", {200, 30, 30}},
                    {"b", {30, 200, 30}},
                    {"c", {30, 30, 200}},
                    {"p", {200, 200, 30}}};
    for (const auto& pic : pictures) {
        std::vector<unsigned char> pixels(64 * 48 * 3);
        for (size_t i = 0; i < pixels.size(); ++i) pixels[i] = pic.rgb[i % 3];
        const std::string path = (dir / (std::string(pic.id) + ".png")).string();
        auto out = OIIO::ImageOutput::create(path);
        out->open(path, OIIO::ImageSpec(64, 48, 3, OIIO::TypeDesc::UINT8));
        out->write_image(OIIO::TypeDesc::UINT8, pixels.data());
        out->close();
    }
    const std::string protocol = (dir / "study.toml").string();
    std::ofstream(protocol) << R"toml(
[study]
name = "web"
break_every = 2
inter_trial_ms = 100

[screens]
consent = "Do you agree to take part?"
instructions = "Rate each picture."
debrief = "Thank you."

[online]
completion_code = "C0DE42"

[[questions]]
id = "translucent"
text = "The object looks translucent."

[[questions]]
id = "realistic"
text = "The object looks realistic."
labels = ["no", "", "", "", "yes"]

[[stimuli]]
id = "a"
image = "a.png"
[[stimuli]]
id = "b"
image = "b.png"
[[stimuli]]
id = "c"
image = "c.png"
[[stimuli]]
id = "p"
image = "p.png"

[practice]
stimuli = ["p"]

[[blocks]]
id = "main"
stimuli = ["a", "b", "c"]

[[catch_trials]]
id = "attention"
stimulus = "a"
block = "main"
prompt = "Attention: choose 5 on both"
expected = 5
)toml";
    return protocol;
}
inline constexpr int kServeStudyTrials = 5;  // 1 practice + 3 rated + 1 catch

// The token key every instance of one study shares (--secret-file): 32 random bytes in
// DIR/serve.key, mode 0600. Returns its path.
inline std::string write_serve_key(const std::filesystem::path& dir) {
    const std::string key = (dir / "serve.key").string();
    std::random_device random;
    std::string bytes(32, '\0');
    for (char& c : bytes) c = static_cast<char>(random());
    std::ofstream(key, std::ios::binary) << bytes;
    std::filesystem::permissions(
        key, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
    return key;
}

class ServeProcess {
public:
    // `state_dir`: the server's journal and key folder (LUCENT_JOURNAL_DIR). An empty
    // `protocol` is left out (a built-in one named by --preset in `extra_args`).
    ServeProcess(const std::string& protocol, const std::string& db,
                 const std::string& state_dir,
                 const std::vector<std::string>& extra_args = {}) {
        int out[2];
        if (pipe(out) != 0) return;
        pid_ = fork();
        if (pid_ == 0) {
            dup2(out[1], 1);
            close(out[0]);
            close(out[1]);
            setenv("LUCENT_JOURNAL_DIR", state_dir.c_str(), 1);
            std::vector<std::string> args = {LUCENT_EXECUTABLE, "serve"};
            if (!protocol.empty())
                args.push_back(protocol);  // else --preset in extra_args
            args.insert(args.end(), {"--db", db});
            // A port of the caller's (--listen in extra_args: an instance restarted
            // behind a proxy keeps its port), else a free one.
            if (std::find(extra_args.begin(), extra_args.end(), "--listen") ==
                extra_args.end())
                args.insert(args.end(), {"--listen", "127.0.0.1:0"});
            args.insert(args.end(), extra_args.begin(), extra_args.end());
            // A server store needs the study's key file (docs/deploy.md): one written
            // for this server unless the caller gives one.
            if (db.rfind("postgresql://", 0) == 0 &&
                std::find(extra_args.begin(), extra_args.end(), "--secret-file") ==
                    extra_args.end())
                args.insert(args.end(), {"--secret-file",
                                         std::filesystem::exists(state_dir + "/serve.key")
                                             ? state_dir + "/serve.key"
                                             : write_serve_key(state_dir)});
            std::vector<char*> argv;
            for (std::string& a : args) argv.push_back(a.data());
            argv.push_back(nullptr);
            execv(LUCENT_EXECUTABLE, argv.data());
            _exit(127);
        }
        close(out[1]);
        // The first line names the address: "... on
        // http://127.0.0.1:PORT/?participant=ID".
        std::string line;
        char c = 0;
        while (read(out[0], &c, 1) == 1 && c != '\n') line += c;
        stdout_ = out[0];
        const size_t at = line.find("http://127.0.0.1:");
        if (at != std::string::npos) port_ = std::stoi(line.substr(at + 17));
        first_line_ = line;
    }
    ~ServeProcess() { stop(); }
    // SIGTERM; the exit status (0 when it stopped cleanly).
    int stop() { return signal_and_wait(SIGTERM); }
    // SIGKILL: the process dies at once, as on a crash or a lost machine; the exit
    // status (128 + 9).
    int kill_now() { return signal_and_wait(SIGKILL); }
    int port() const { return port_; }
    const std::string& first_line() const { return first_line_; }
    std::string url() const { return "http://127.0.0.1:" + std::to_string(port_); }

private:
    int signal_and_wait(int signal) {
        if (pid_ <= 0) return exit_status_;
        kill(pid_, signal);
        int status = 0;
        waitpid(pid_, &status, 0);
        pid_ = -1;
        if (stdout_ >= 0) close(stdout_);
        stdout_ = -1;
        exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        return exit_status_;
    }

    int pid_ = -1;
    int stdout_ = -1;
    int port_ = 0;
    int exit_status_ = -1;
    std::string first_line_;
};

// A free TCP port on loopback now (bound, read back and released: a server started
// right after takes it, barring a race with another process).
inline int free_loopback_port() {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t size = sizeof addr;
    int port = 0;
    if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0 &&
        ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &size) == 0)
        port = ntohs(addr.sin_port);
    ::close(fd);
    return port;
}

// Instance `index` of several on one database: its own port and state folder
// (DIR/instanceN), the shared key; started again the same way after it was killed.
inline std::unique_ptr<ServeProcess> start_serve_instance(
    const std::string& protocol, const std::string& db, const std::filesystem::path& dir,
    int index, int port, const std::string& key) {
    const std::filesystem::path state = dir / ("instance" + std::to_string(index));
    std::filesystem::create_directories(state);
    return std::make_unique<ServeProcess>(
        protocol, db, state.string(),
        std::vector<std::string>{"--listen", "127.0.0.1:" + std::to_string(port),
                                 "--secret-file", key, "--store-connections", "4"});
}

// The API over HTTP, one keep-alive connection per page.
inline Transport over_http(httplib::Client& client) {
    return [&client](const std::string& endpoint, const std::string& body) {
        const auto r =
            client.Post(("/api/" + endpoint).c_str(), body, "application/json");
        if (!r)
            return study::WebReply{
                0, json{{"error", "no reply: " + httplib::to_string(r.error())}}.dump()};
        study::WebReply reply{r->status, r->body};
        if (r->has_header("Retry-After"))
            reply.retry_after_s = std::atoi(r->get_header_value("Retry-After").c_str());
        return reply;
    };
}

}  // namespace lucent::test
