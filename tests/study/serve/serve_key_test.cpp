// The session key of `lucent serve` (issue 44, item 1): a server store without
// --secret-file is refused (an instance with a key of its own would strand every page
// another instance started), a key file others may read or a key with too little
// entropy is refused in one line, and /healthz names the key's fingerprint, equal on
// instances given one file.
#include <gtest/gtest.h>
#include <httplib.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "study/serve/web_study.h"
#include "tests/study/serve/serve_process.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

struct ServeRun {
    int status = -1;
    std::string output;  // stdout and stderr
};

ServeRun run_serve(const std::string& args) {
    const std::string command =
        std::string(LUCENT_EXECUTABLE) + " serve " + args + " 2>&1";
    ServeRun run;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return run;
    char buffer[512];
    while (fgets(buffer, sizeof buffer, pipe)) run.output += buffer;
    const int status = pclose(pipe);
    run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return run;
}

std::string write_key(const std::filesystem::path& path, const std::string& bytes,
                      std::filesystem::perms perms) {
    std::ofstream(path, std::ios::binary) << bytes;
    std::filesystem::permissions(path, perms);
    return path.string();
}

constexpr auto kOwnerOnly =
    std::filesystem::perms::owner_read | std::filesystem::perms::owner_write;

TEST(ServeKey, AServerStoreWithoutAKeyFileIsRefusedInOneLine) {
    const auto dir = lucent::test::scratch_dir("serve_key_server");
    const std::string study = lucent::test::write_serve_study(dir);
    // Refused before any connection is tried: no server needs to listen there.
    const ServeRun run = run_serve(study + " --db postgresql://lucent@127.0.0.1:1/none");
    EXPECT_EQ(run.status, 2) << run.output;
    EXPECT_NE(run.output.find("needs --secret-file"), std::string::npos) << run.output;
    EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
}

TEST(ServeKey, KeyFilesOthersMayReadOrWithLittleEntropyAreRefused) {
    const auto dir = lucent::test::scratch_dir("serve_key_files");
    const std::string study = lucent::test::write_serve_study(dir);
    const std::string db = (dir / "study.db").string();
    std::string random(32, '\0');
    for (size_t i = 0; i < random.size(); ++i) random[i] = static_cast<char>(i * 37 + 11);
    struct Case {
        std::string name, bytes;
        std::filesystem::perms perms;
        std::string says;
    } cases[] = {
        {"readable.key", random,
         kOwnerOnly | std::filesystem::perms::group_read |
             std::filesystem::perms::others_read,
         "mode 0644"},
        {"short.key", random.substr(0, 31), kOwnerOnly, "shorter than 32 bytes"},
        {"zeros.key", std::string(64, '\0'), kOwnerOnly, "too little entropy"},
        {"pattern.key", std::string(40, 'a') + std::string(40, 'b'), kOwnerOnly,
         "too little entropy"},
    };
    for (const Case& c : cases) {
        const std::string key = write_key(dir / c.name, c.bytes, c.perms);
        const ServeRun run = run_serve(study + " --images " + dir.string() + " --db " +
                                       db + " --listen 127.0.0.1:0 --secret-file " + key);
        EXPECT_NE(run.status, 0) << c.name << ": " << run.output;
        EXPECT_NE(run.output.find(key), std::string::npos)
            << c.name << ": " << run.output;
        EXPECT_NE(run.output.find(c.says), std::string::npos)
            << c.name << ": " << run.output;
        EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1)
            << c.name << ": " << run.output;
    }
}

TEST(ServeKey, HealthzNamesTheKeysFingerprintTheSameForOneKeyFile) {
    const auto dir = lucent::test::scratch_dir("serve_key_health");
    const std::string study = lucent::test::write_serve_study(dir);
    const std::string db = (dir / "study.db").string();
    const std::string key = lucent::test::write_serve_key(dir);
    std::ifstream in(key, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    std::filesystem::create_directories(dir / "a");
    std::filesystem::create_directories(dir / "b");
    lucent::test::ServeProcess a(study, db, (dir / "a").string(),
                                 {"--images", dir.string(), "--secret-file", key});
    lucent::test::ServeProcess other(study, db, (dir / "b").string(),
                                     {"--images", dir.string()});  // its own default key
    ASSERT_GT(a.port(), 0) << a.first_line();
    ASSERT_GT(other.port(), 0) << other.first_line();
    auto key_of = [](int port) {
        httplib::Client http("127.0.0.1", port);
        const auto r = http.Get("/healthz");
        EXPECT_TRUE(r);
        if (!r) return std::string();
        EXPECT_EQ(r->status, 200) << r->body;
        return nlohmann::json::parse(r->body).value("key", "");
    };
    EXPECT_EQ(key_of(a.port()), key_fingerprint(bytes));
    EXPECT_EQ(key_of(a.port()).size(), 16u);
    EXPECT_NE(key_of(other.port()), key_of(a.port()));
    // The fingerprint tells nothing of the key's bytes.
    EXPECT_EQ(key_of(a.port()).find_first_not_of("0123456789abcdef"), std::string::npos);
}

}  // namespace
}  // namespace lucent::study
