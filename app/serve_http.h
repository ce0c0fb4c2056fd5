#pragma once
// lucent serve's HTTP layer (cpp-httplib), shared by `lucent serve` and `lucent bench
// store`: the page, the pictures from memory, and each API request handed to WebStudy.
#include <httplib.h>

#include <chrono>
#include <map>
#include <string>

#include "study/serve/web_study.h"

namespace lucent::app {

struct ServedPicture {
    std::string png;  // the bytes served
    study::WebImage size;
};

struct ServeHttpLimits {
    int threads = 64;  // workers: connections served at once
    // Each request (its line, headers and body, read and answered) must be done this
    // long after the connection's worker took it up or after the previous reply on the
    // connection; a slower one (a slowloris client trickling header lines) has its
    // connection cut, so it holds a worker no longer than this.
    std::chrono::milliseconds request_deadline = std::chrono::seconds(5);
    // The longest wait for the next bytes of a request (cpp-httplib's read timeout).
    std::chrono::milliseconds read_timeout = std::chrono::seconds(5);
};

// Routes, limits (64 KiB bodies, the timeouts of `limits`), security headers and JSON
// errors on `http`. `web` and `pictures` must outlive the server.
void configure_serve_http(httplib::Server& http, study::WebStudy& web,
                          const std::map<std::string, ServedPicture>& pictures,
                          const ServeHttpLimits& limits);
inline void configure_serve_http(httplib::Server& http, study::WebStudy& web,
                                 const std::map<std::string, ServedPicture>& pictures,
                                 int threads) {
    ServeHttpLimits limits;
    limits.threads = threads;
    configure_serve_http(http, web, pictures, limits);
}
// Binds host:port (0: a free port) with a deep accept queue; the port, or -1 (errno).
int bind_serve_port(httplib::Server& http, const std::string& host, int port);

}  // namespace lucent::app
