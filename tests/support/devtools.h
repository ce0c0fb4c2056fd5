#pragma once
// A real browser driven as a person would use it, for tests of pages that need input:
// Debian's chromium, headless, with a fresh profile, controlled over the DevTools
// protocol on a pipe (--remote-debugging-pipe: JSON messages ended by NUL on file
// descriptors 3 and 4), so no port is opened and no WebSocket client is needed.
// Keys and clicks go through Input.dispatchKeyEvent / dispatchMouseEvent, the same path
// as real input (trusted events, with their own timestamps).
#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace lucent::test {

class DevToolsBrowser {
public:
    // Starts chromium with a page of width x height CSS pixels. ok() says whether it
    // started; error() why not (one line).
    DevToolsBrowser(int width = 1280, int height = 1024);
    ~DevToolsBrowser();
    DevToolsBrowser(const DevToolsBrowser&) = delete;
    DevToolsBrowser& operator=(const DevToolsBrowser&) = delete;

    bool ok() const { return session_.size() > 0; }
    const std::string& error() const { return error_; }

    // One DevTools command on the page; its result, or throws std::runtime_error with
    // the browser's error or a timeout.
    nlohmann::json call(const std::string& method,
                        nlohmann::json params = nlohmann::json::object());
    void navigate(const std::string& url);
    void reload();
    // The value of a JavaScript expression (promises awaited).
    nlohmann::json evaluate(const std::string& expression);
    // Polls `expression` until it is true; false after `timeout`.
    bool wait_until(const std::string& expression,
                    std::chrono::milliseconds timeout = std::chrono::seconds(10));
    // A key press and release: "1".."9", "Enter", "ArrowLeft", "ArrowRight", "ArrowUp",
    // "ArrowDown", or a letter.
    void press(const std::string& key);
    // A left click at the centre of the first element matching the CSS selector; false
    // when none is shown.
    bool click(const std::string& selector);

private:
    nlohmann::json call_on(const std::string& session, const std::string& method,
                           nlohmann::json params);
    nlohmann::json read_reply(int id);

    int pid_ = -1;
    int to_browser_ = -1, from_browser_ = -1;
    std::filesystem::path profile_;
    std::string session_;
    std::string error_;
    std::string pending_;  // bytes read past the last message
    int next_id_ = 1;
};

}  // namespace lucent::test
