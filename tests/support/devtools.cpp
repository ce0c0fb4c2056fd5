#include "tests/support/devtools.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <stdexcept>
#include <thread>

namespace lucent::test {

using nlohmann::json;

namespace {
constexpr auto kReplyTimeout = std::chrono::seconds(30);
}

DevToolsBrowser::DevToolsBrowser(int width, int height) {
    if (std::system("command -v chromium > /dev/null 2>&1") != 0) {
        error_ =
            "chromium is not installed (Debian package chromium; scripts/install-deps)";
        return;
    }
    char profile_template[] = "/tmp/lucent-devtools-XXXXXX";
    if (!mkdtemp(profile_template)) {
        error_ = "cannot create a profile folder in /tmp";
        return;
    }
    profile_ = profile_template;
    int to[2], from[2];
    if (pipe(to) != 0 || pipe(from) != 0) {
        error_ = std::string("pipe: ") + std::strerror(errno);
        return;
    }
    const std::string size =
        "--window-size=" + std::to_string(width) + "," + std::to_string(height);
    const std::string profile = "--user-data-dir=" + profile_.string();
    pid_ = fork();
    if (pid_ == 0) {
        // The child: its own process group (so the test can end chromium's helpers with
        // it), the pipe on descriptors 3 (commands in) and 4 (replies out).
        setpgid(0, 0);
        dup2(to[0], 3);
        dup2(from[1], 4);
        for (int fd : {to[0], to[1], from[0], from[1]})
            if (fd > 4) close(fd);
        const int null = open("/dev/null", O_RDWR);
        dup2(null, 0);
        dup2(null, 1);
        dup2(null, 2);
        const char* argv[] = {"chromium",
                              "--headless",
                              "--no-sandbox",
                              "--disable-gpu",
                              "--disable-quic",
                              "--no-first-run",
                              "--disable-background-networking",
                              "--disable-component-update",
                              "--disable-sync",
                              "--hide-scrollbars",
                              "--mute-audio",
                              "--remote-debugging-pipe",
                              size.c_str(),
                              profile.c_str(),
                              "about:blank",
                              nullptr};
        execvp("chromium", const_cast<char* const*>(argv));
        _exit(127);
    }
    close(to[0]);
    close(from[1]);
    to_browser_ = to[1];
    from_browser_ = from[0];
    if (pid_ < 0) {
        error_ = std::string("fork: ") + std::strerror(errno);
        return;
    }
    try {
        // The page chromium opened, attached with a flat session for its commands.
        const json targets = call_on("", "Target.getTargets", json::object());
        std::string target;
        for (const json& t : targets["targetInfos"])
            if (t["type"] == "page") target = t["targetId"];
        if (target.empty())
            target =
                call_on("", "Target.createTarget", {{"url", "about:blank"}})["targetId"];
        session_ = call_on("", "Target.attachToTarget",
                           {{"targetId", target}, {"flatten", true}})["sessionId"];
        call("Page.enable");
        call("Runtime.enable");
    } catch (const std::exception& e) {
        error_ = std::string("chromium over DevTools: ") + e.what();
        session_.clear();
    }
}

DevToolsBrowser::~DevToolsBrowser() {
    if (pid_ > 0) {
        try {
            if (to_browser_ >= 0) {
                const std::string close_message =
                    json{{"id", next_id_++}, {"method", "Browser.close"}}.dump() + '\0';
                (void)!write(to_browser_, close_message.data(), close_message.size());
            }
        } catch (...) {
        }
        // A moment to close by itself, then the process group is ended.
        for (int i = 0; i < 50; ++i) {
            if (waitpid(pid_, nullptr, WNOHANG) == pid_) {
                pid_ = -1;
                break;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        if (pid_ > 0) {
            kill(-pid_, SIGKILL);
            waitpid(pid_, nullptr, 0);
        }
    }
    if (to_browser_ >= 0) close(to_browser_);
    if (from_browser_ >= 0) close(from_browser_);
    std::error_code ignored;
    if (!profile_.empty()) std::filesystem::remove_all(profile_, ignored);
}

json DevToolsBrowser::call(const std::string& method, json params) {
    return call_on(session_, method, std::move(params));
}

json DevToolsBrowser::call_on(const std::string& session, const std::string& method,
                              json params) {
    const int id = next_id_++;
    json message = {{"id", id}, {"method", method}, {"params", std::move(params)}};
    if (!session.empty()) message["sessionId"] = session;
    const std::string bytes = message.dump() + '\0';
    for (size_t sent = 0; sent < bytes.size();) {
        const ssize_t n = write(to_browser_, bytes.data() + sent, bytes.size() - sent);
        if (n <= 0)
            throw std::runtime_error("cannot write to chromium: " +
                                     std::string(std::strerror(errno)));
        sent += static_cast<size_t>(n);
    }
    return read_reply(id);
}

json DevToolsBrowser::read_reply(int id) {
    const auto deadline = std::chrono::steady_clock::now() + kReplyTimeout;
    for (;;) {
        // Whole messages already read: events are skipped, the reply returned.
        for (size_t end = pending_.find('\0'); end != std::string::npos;
             end = pending_.find('\0')) {
            const json message = json::parse(pending_.substr(0, end), nullptr, false);
            pending_.erase(0, end + 1);
            if (!message.is_object() || !message.contains("id") || message["id"] != id)
                continue;
            if (message.contains("error"))
                throw std::runtime_error(
                    message["error"].value("message", std::string("error")));
            return message.value("result", json::object());
        }
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
            deadline - std::chrono::steady_clock::now());
        if (left.count() <= 0) throw std::runtime_error("no reply from chromium in 30 s");
        pollfd p{from_browser_, POLLIN, 0};
        if (poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
        char buffer[65536];
        const ssize_t n = read(from_browser_, buffer, sizeof buffer);
        if (n <= 0) throw std::runtime_error("chromium closed the DevTools pipe");
        pending_.append(buffer, static_cast<size_t>(n));
    }
}

void DevToolsBrowser::navigate(const std::string& url) {
    call("Page.navigate", {{"url", url}});
}

void DevToolsBrowser::reload() { call("Page.reload", {{"ignoreCache", true}}); }

json DevToolsBrowser::evaluate(const std::string& expression) {
    const json result = call(
        "Runtime.evaluate",
        {{"expression", expression}, {"returnByValue", true}, {"awaitPromise", true}});
    if (result.contains("exceptionDetails"))
        throw std::runtime_error("JavaScript: " + result["exceptionDetails"].dump());
    return result["result"].value("value", json());
}

bool DevToolsBrowser::wait_until(const std::string& expression,
                                 std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
        try {
            if (evaluate("Boolean(" + expression + ")") == true) return true;
        } catch (const std::exception&) {
            // A page being replaced (navigation, reload) has no context for a moment.
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
}

void DevToolsBrowser::press(const std::string& key) {
    // The fields a real keyboard event carries: key, code, the Windows key code, and the
    // text a printable key types.
    json down = {{"type", "keyDown"}, {"key", key}};
    if (key.size() == 1 && std::isdigit(static_cast<unsigned char>(key[0]))) {
        down["code"] = "Digit" + key;
        down["windowsVirtualKeyCode"] = static_cast<int>(key[0]);
        down["text"] = key;
    } else if (key.size() == 1) {
        down["code"] =
            std::string("Key") + char(std::toupper(static_cast<unsigned char>(key[0])));
        down["windowsVirtualKeyCode"] = std::toupper(static_cast<unsigned char>(key[0]));
        down["text"] = key;
    } else if (key == "Enter") {
        down["code"] = "Enter";
        down["windowsVirtualKeyCode"] = 13;
        down["text"] = "\r";
    } else {
        const int code = key == "ArrowLeft"    ? 37
                         : key == "ArrowUp"    ? 38
                         : key == "ArrowRight" ? 39
                                               : 40;
        down["code"] = key;
        down["windowsVirtualKeyCode"] = code;
    }
    call("Input.dispatchKeyEvent", down);
    json up = down;
    up["type"] = "keyUp";
    up.erase("text");
    call("Input.dispatchKeyEvent", up);
}

bool DevToolsBrowser::click(const std::string& selector) {
    const json box = evaluate(
        "(() => { const e = document.querySelector(" + json(selector).dump() +
        "); if (!e) return null; const r = e.getBoundingClientRect(); "
        "return r.width > 0 ? [r.left + r.width / 2, r.top + r.height / 2] : null; })()");
    if (!box.is_array()) return false;
    json mouse = {{"x", box[0]}, {"y", box[1]}, {"button", "left"}, {"clickCount", 1}};
    mouse["type"] = "mousePressed";
    call("Input.dispatchMouseEvent", mouse);
    mouse["type"] = "mouseReleased";
    call("Input.dispatchMouseEvent", mouse);
    return true;
}

}  // namespace lucent::test
