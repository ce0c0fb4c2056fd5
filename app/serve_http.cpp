// lucent serve's HTTP layer (serve_http.h).
#include "serve_http.h"

#include <sys/socket.h>

#include <nlohmann/json.hpp>

#include "serve/web_files.h"

namespace lucent::app {
namespace {

std::string one_line_json_error(const std::string& why) {
    std::string line = why;
    for (char& c : line)
        if (static_cast<unsigned char>(c) < 0x20) c = ' ';
    return nlohmann::json{{"error", line}}.dump(-1, ' ', false,
                                                nlohmann::json::error_handler_t::replace);
}

}  // namespace

void configure_serve_http(httplib::Server& http, study::WebStudy& web,
                          const std::map<std::string, ServedPicture>& pictures, int threads) {
    http.new_task_queue = [threads] { return new httplib::ThreadPool(static_cast<size_t>(threads)); };
    http.set_tcp_nodelay(true);  // each reply at once: no Nagle wait for a delayed ACK
    http.set_payload_max_length(64 * 1024);  // larger bodies: 413 before they are read
    http.set_read_timeout(10);
    http.set_write_timeout(10);
    http.set_keep_alive_timeout(2);
    http.set_default_headers({{"X-Content-Type-Options", "nosniff"},
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
    std::map<std::string, study::WebImage> sizes;
    for (const auto& [id, picture] : pictures) sizes[id] = picture.size;
    http.Get(R"(/images/.*)", [sizes, &pictures](const httplib::Request& req, httplib::Response& res) {
        // Matched on the raw target, so no decoding here can turn a name into a path.
        const std::optional<std::string> id = study::image_of_target(req.target, sizes);
        if (!id) {
            res.status = 404;
            res.set_content(one_line_json_error("no such picture: " + req.target), "application/json");
            return;
        }
        res.set_header("Cache-Control", "private, max-age=3600");
        res.set_content(pictures.at(*id).png, "image/png");
    });
    http.Post(R"(/api/([a-z_]+))", [&web](const httplib::Request& req, httplib::Response& res) {
        const study::WebReply reply = web.handle(req.matches[1].str(), req.body);
        res.status = reply.status;
        res.set_content(reply.body, "application/json");
    });
    http.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
        if (!res.body.empty()) return;
        const std::string why = res.status == 413 ? "request body over 65536 bytes"
                                : res.status == 404 ? "not found: " + req.method + " " + req.target
                                                    : "HTTP " + std::to_string(res.status);
        res.set_content(one_line_json_error(why), "application/json");
    });
    http.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr) {
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
