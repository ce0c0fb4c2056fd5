#pragma once
// lucent serve's HTTP layer (cpp-httplib), shared by `lucent serve` and `lucent bench
// store`: the page, the pictures from memory, and each API request handed to WebStudy.
#include <httplib.h>

#include <map>
#include <string>

#include "serve/web_study.h"

namespace lucent::app {

struct ServedPicture {
    std::string png;  // the bytes served
    study::WebImage size;
};

// Routes, limits (64 KiB bodies, 10 s timeouts), security headers and JSON errors on
// `http`; `threads` workers serve that many connections at once. `web` and `pictures`
// must outlive the server.
void configure_serve_http(httplib::Server& http, study::WebStudy& web,
                          const std::map<std::string, ServedPicture>& pictures, int threads);
// Binds host:port (0: a free port) with a deep accept queue; the port, or -1 (errno).
int bind_serve_port(httplib::Server& http, const std::string& host, int port);

}  // namespace lucent::app
