// The documented start of a built-in study from its pictures, command for command (issue
// 26 item 9): `lucent render --preset NAME --out DIR`, then `lucent serve --preset NAME
// --images DIR ...` and `lucent run --preset NAME --images DIR ...` from the folder that
// render wrote. The three command lines are read as written from README.md and the pages
// of docs/ (they must be on at least one, in that order, and the same wherever they are
// shown) and run in a scratch folder; the test adds only what a test needs:
// `--listen 127.0.0.1:0` to serve (a free port) and the autopilot participant to run. For
// `fabrics` the same lines run with the study's name in place of `thesis`.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "study/protocol.h"
#include "study/serve/picture_names.h"
#include "study/session/stimulus_source.h"
#include "study/sqlite/database.h"
#include "study/trial_plan.h"
#include "study/web_series.h"
#include "tests/support/display.h"
#include "tests/support/test_paths.h"

namespace lucent {
namespace {

namespace fs = std::filesystem;

std::string read_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

std::vector<std::string> words(const std::string& line) {
    std::istringstream in(line);
    std::vector<std::string> out;
    for (std::string w; in >> w;) out.push_back(w);
    return out;
}

// The pages a user reads: README.md and every page of docs/.
std::vector<fs::path> documentation_pages() {
    std::vector<fs::path> pages{test::source_dir() / "README.md"};
    for (const fs::directory_entry& entry :
         fs::directory_iterator(test::source_dir() / "docs"))
        if (entry.path().extension() == ".md") pages.push_back(entry.path());
    return pages;
}

// Every block of the online start's three command lines in `page`: three indented lines
// in a row, `lucent render --preset thesis ...`, `lucent serve ...`, `lucent run ...`.
std::vector<std::vector<std::string>> start_blocks(const fs::path& page) {
    std::istringstream text(read_file(page));
    std::vector<std::string> lines;
    for (std::string line; std::getline(text, line);) lines.push_back(line);
    std::vector<std::vector<std::string>> blocks;
    for (size_t i = 0; i + 2 < lines.size(); ++i) {
        if (lines[i].rfind("    lucent render --preset thesis --out ", 0) != 0) continue;
        if (lines[i + 1].rfind("    lucent serve --preset thesis --images ", 0) != 0)
            continue;
        if (lines[i + 2].rfind("    lucent run --preset thesis --images ", 0) != 0)
            continue;
        blocks.push_back({lines[i], lines[i + 1], lines[i + 2]});
    }
    return blocks;
}

// The documented three lines; empty when no page shows them. Every page that shows them
// must show the same lines (so the lines run here are the ones each reader sees).
std::vector<std::string> documented_start_commands() {
    std::vector<std::string> first;
    fs::path first_page;
    for (const fs::path& page : documentation_pages())
        for (const std::vector<std::string>& block : start_blocks(page)) {
            if (first.empty()) {
                first = block;
                first_page = page;
            }
            EXPECT_EQ(block, first)
                << page << " shows other start commands than " << first_page;
        }
    return first;
}

// `line` for study `name` (the pages write thesis), as argv after "lucent".
std::vector<std::string> args_of(std::string line, const std::string& name) {
    for (size_t at = 0; (at = line.find("thesis", at)) != std::string::npos;
         at += name.size())
        line.replace(at, 6, name);
    std::vector<std::string> w = words(line);
    w.erase(w.begin());  // "lucent"
    return w;
}

struct Child {
    pid_t pid = -1;
    int stdout_fd = -1;
    fs::path stderr_path;
};

// Starts lucent with `args` in `cwd`; stdout to a pipe (read by the caller) or a file.
Child start(const std::vector<std::string>& args, const fs::path& cwd,
            const std::string& tag, bool pipe_stdout) {
    Child c;
    c.stderr_path = cwd / (tag + ".stderr");
    const fs::path out_path = cwd / (tag + ".stdout");
    int out[2] = {-1, -1};
    if (pipe_stdout && pipe(out) != 0) return c;
    c.pid = fork();
    if (c.pid == 0) {
        if (chdir(cwd.c_str()) != 0) _exit(126);
        const int err = open(c.stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(err, 2);
        if (pipe_stdout) {
            dup2(out[1], 1);
            close(out[0]);
            close(out[1]);
        } else {
            const int fd = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
            dup2(fd, 1);
        }
        std::vector<char*> argv{const_cast<char*>(LUCENT_EXECUTABLE)};
        for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        execv(LUCENT_EXECUTABLE, argv.data());
        _exit(127);
    }
    if (pipe_stdout) {
        close(out[1]);
        c.stdout_fd = out[0];
    }
    return c;
}

int wait_exit(Child& c, bool terminate = false) {
    if (c.pid <= 0) return -1;
    if (terminate) kill(c.pid, SIGTERM);
    int status = 0;
    waitpid(c.pid, &status, 0);
    c.pid = -1;
    if (c.stdout_fd >= 0) close(c.stdout_fd);
    c.stdout_fd = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string first_line(int fd) {
    std::string line;
    char ch = 0;
    while (read(fd, &ch, 1) == 1 && ch != '\n') line += ch;
    return line;
}

// The URL a serve instance holding the study's key (`key_file`) gives picture `id`
// (study/serve/picture_names.h): the test mints it as a second instance would, since
// no picture is served by its stimulus id.
std::string picture_url(const fs::path& key_file, const study::Protocol& protocol,
                        const std::string& id) {
    const study::Protocol shown =
        study::with_series_pictures(protocol, study::web_series(protocol));
    std::vector<std::string> ids;
    for (const Stimulus& s : shown.stimuli) ids.push_back(s.id);
    return study::PictureNames(read_file(key_file), ids).url("documented start", 0, id);
}

// The key file a `serve` command line uses: --secret-file, else beside its --db.
fs::path key_file_of(const std::vector<std::string>& args, const fs::path& dir) {
    const auto secret = std::find(args.begin(), args.end(), "--secret-file");
    if (secret != args.end()) return dir / *(secret + 1);
    return dir / (*(std::find(args.begin(), args.end(), "--db") + 1) + "-serve-key");
}

void documented_start(const std::string& name) {
    LUCENT_REQUIRE_DISPLAY();
    const std::vector<std::string> documented = documented_start_commands();
    ASSERT_EQ(documented.size(), 3u)
        << "neither README.md nor docs/ has a block of the three lines 'lucent render "
           "--preset thesis --out DIR', 'lucent serve --preset thesis --images DIR ...', "
           "'lucent run --preset thesis --images DIR ...'";
    const fs::path dir = test::scratch_dir("documented_start");
    const study::Protocol protocol = study::builtin_protocol(name);

    // 1. lucent render --preset NAME --out DIR: every picture the study shows.
    const std::vector<std::string> render = args_of(documented[0], name);
    Child r = start(render, dir, "render", false);
    ASSERT_EQ(wait_exit(r), 0) << read_file(r.stderr_path);
    const fs::path pictures = dir / render.back();
    for (const Stimulus& s : protocol.stimuli)
        EXPECT_TRUE(fs::exists(pictures / (s.id + ".png"))) << s.id;
    for (const std::string& id : protocol.practice) {
        const std::string manifest = read_file(pictures / "manifest.csv");
        EXPECT_NE(manifest.find("\n" + id + ","), std::string::npos)
            << id << " has no manifest row";
    }

    // 2. lucent serve --preset NAME --images DIR --db study.db: starts, and a participant
    // gets the consent screen; the practice pictures are served.
    std::vector<std::string> serve = args_of(documented[1], name);
    serve.insert(serve.end(), {"--listen", "127.0.0.1:0"});
    Child s = start(serve, dir, "serve", true);
    const std::string line = first_line(s.stdout_fd);
    const size_t at = line.find("http://127.0.0.1:");
    if (at == std::string::npos) {
        const int code = wait_exit(s, true);
        FAIL() << "serve did not start (exit " << code << "): " << line
               << read_file(s.stderr_path);
    }
    {
        httplib::Client client("127.0.0.1", std::stoi(line.substr(at + 17)));
        const auto session = client.Post(
            "/api/session", R"({"participant": "WEB1", "t_ms": 0})", "application/json");
        ASSERT_TRUE(session) << httplib::to_string(session.error());
        EXPECT_EQ(session->status, 200) << session->body;
        EXPECT_NE(session->body.find("\"screen\":\"consent\""), std::string::npos)
            << session->body;
        for (const std::string& id : protocol.practice) {
            const auto png =
                client.Get(picture_url(key_file_of(serve, dir), protocol, id).c_str());
            ASSERT_TRUE(png) << id;
            EXPECT_EQ(png->status, 200) << id;
            EXPECT_EQ(png->body.substr(1, 3), "PNG") << id;
        }
    }
    EXPECT_EQ(wait_exit(s, true), 0) << read_file(s.stderr_path);

    // 3. lucent run --preset NAME --images DIR --db study.db --participant P01: the
    // whole session, every picture from the folder.
    std::vector<std::string> run = args_of(documented[2], name);
    run.insert(run.end(), {"--autopilot", "3", "--autopilot-speed", "25"});
    Child l = start(run, dir, "run", false);
    ASSERT_EQ(wait_exit(l), 0) << read_file(l.stderr_path);
    std::string db, participant;
    for (size_t i = 0; i + 1 < run.size(); ++i) {
        if (run[i] == "--db") db = run[i + 1];
        if (run[i] == "--participant") participant = run[i + 1];
    }
    study::Database d((dir / db).string(), SQLITE_OPEN_READONLY);
    const std::string session =
        "(SELECT s.id FROM sessions s JOIN participants p ON p.id = s.participant_id "
        "WHERE "
        "p.code = '" +
        participant + "' AND s.status = 'completed')";
    const int64_t trials =
        d.scalar_int("SELECT count(*) FROM trials WHERE session_id = " + session);
    EXPECT_EQ(trials,
              static_cast<int64_t>(study::plan_trials(protocol, 1, 1).trials.size()));
    EXPECT_EQ(
        d.scalar_int("SELECT count(*) FROM trials WHERE practice = 1 AND session_id = " +
                     session),
        static_cast<int64_t>(protocol.practice.size()));
    EXPECT_EQ(
        d.scalar_int("SELECT count(*) FROM responses WHERE session_id = " + session),
        trials * static_cast<int64_t>(protocol.questions.size()));
    // Every picture came from the folder (none rendered live), practice included.
    EXPECT_EQ(d.scalar_int(
                  "SELECT count(*) FROM segment_stimuli ss JOIN session_segments g ON "
                  "g.id = ss.segment_id WHERE ss.source = 'images' AND g.session_id = " +
                  session),
              static_cast<int64_t>(protocol.stimuli.size()));
}

TEST(DocumentedStart, ThesisRunsAndServesFromTheSetItsRenderPresetWrites) {
    documented_start("thesis");
}

TEST(DocumentedStart, FabricsRunsAndServesFromTheSetItsRenderPresetWrites) {
    documented_start("fabrics");
}

// A page of docs/'s `lucent` command lines, in order: each indented line starting
// `lucent ` (a trailing backslash continues it; `# ...` is a comment).
std::vector<std::string> page_commands(const std::string& name) {
    std::istringstream page(read_file(test::source_dir() / "docs" / name));
    std::vector<std::string> commands;
    std::string pending;
    for (std::string line; std::getline(page, line);) {
        if (pending.empty() && line.rfind("    lucent ", 0) != 0) continue;
        line = line.substr(0, line.find('#'));
        const bool continues = !line.empty() &&
                               line.find_last_not_of(' ') != std::string::npos &&
                               line[line.find_last_not_of(' ')] == '\\';
        pending += continues ? line.substr(0, line.find_last_not_of(' ')) + " " : line;
        if (!continues) {
            commands.push_back(pending);
            pending.clear();
        }
    }
    return commands;
}

// Starts `lucent serve ARGS` on a free port in `dir`; the port it listens on, or 0 when
// it did not start (its stderr says why).
int start_serve(std::vector<std::string> args, const fs::path& dir, Child& serve) {
    args.insert(args.end(), {"--listen", "127.0.0.1:0"});
    serve = start(args, dir, "serve", true);
    const std::string line = first_line(serve.stdout_fd);
    const size_t at = line.find("http://127.0.0.1:");
    return at == std::string::npos ? 0 : std::stoi(line.substr(at + 17));
}

// Runs a page's commands in `dir`, in order, each as written and each to succeed, but
// for what a test needs: the lab session without the autopilot is left out (the line
// with the autopilot is that command with a simulated participant), and `serve` gets a
// free port, a participant's first request (the consent screen), `check` with its
// arguments and a client, and is stopped. Returns how many of each subcommand ran.
std::map<std::string, int> run_page(
    const std::vector<std::string>& commands, const fs::path& dir,
    const std::function<void(const std::vector<std::string>&, httplib::Client&)>& check) {
    std::map<std::string, int> ran;
    for (const std::string& command : commands) {
        std::vector<std::string> args = words(command);
        args.erase(args.begin());  // "lucent"
        const bool autopilot =
            std::find(args.begin(), args.end(), "--autopilot") != args.end();
        if (args[0] == "run" && !autopilot) continue;
        if (args[0] == "serve") {
            Child s;
            const int port = start_serve(args, dir, s);
            EXPECT_GT(port, 0) << read_file(s.stderr_path);
            if (port > 0) {
                httplib::Client client("127.0.0.1", port);
                const auto session =
                    client.Post("/api/session", R"({"participant": "WEB1", "t_ms": 0})",
                                "application/json");
                EXPECT_TRUE(session) << httplib::to_string(session.error());
                if (session) EXPECT_EQ(session->status, 200) << session->body;
                check(args, client);
            }
            EXPECT_EQ(wait_exit(s, true), 0) << read_file(s.stderr_path);
            ++ran["serve"];
            continue;
        }
        Child c = start(args, dir, args[0], false);
        EXPECT_EQ(wait_exit(c), 0) << command << "\n" << read_file(c.stderr_path);
        ++ran[args[0]];
    }
    return ran;
}

// docs/scaling.md, command for command: each indented `lucent` line (a trailing
// backslash continues it; `# ...` is a comment) runs as written in a scratch folder, in
// the page's order, and each must succeed. Two lines get what a test needs: `serve` a
// free port (it is checked and stopped), and the lab session without the autopilot is
// left out (the autopilot line below it is that command with the simulated observer).
TEST(DocumentedScaling, ThePagesCommandsRunAsWrittenAndTheReportScalesTheSession) {
    LUCENT_REQUIRE_DISPLAY();
    const std::vector<std::string> commands = page_commands("scaling.md");
    ASSERT_GE(commands.size(), 7u);
    const fs::path dir = test::scratch_dir("documented_scaling");
    const std::map<std::string, int> ran =
        run_page(commands, dir, [](const std::vector<std::string>&, httplib::Client&) {});
    const bool ran_session = ran.count("run") > 0, analyzed = ran.count("analyze") > 0;
    ASSERT_TRUE(ran_session);
    ASSERT_TRUE(analyzed);
    // The autopilot's session completed, every planned trial answered once, and the
    // report scaled both blocks.
    const study::Protocol protocol = study::builtin_protocol("scaling");
    study::Database d((dir / "scaling.db").string(), SQLITE_OPEN_READONLY);
    EXPECT_EQ(d.scalar_int("SELECT count(*) FROM sessions WHERE status = 'completed'"),
              1);
    EXPECT_EQ(d.scalar_int("SELECT count(*) FROM responses"),
              static_cast<int64_t>(study::plan_trials(protocol, 1, 1).trials.size()));
    EXPECT_EQ(
        d.scalar_int("SELECT count(*) FROM trials t WHERE NOT EXISTS (SELECT 1 FROM "
                     "responses r WHERE r.trial_id = t.id)"),
        0);
    const std::string report = read_file(dir / "report" / "report.md");
    EXPECT_NE(report.find("mlds: differs_more (difference scaling, MLDS)"),
              std::string::npos)
        << report.substr(0, 2000);
    EXPECT_NE(report.find("pairs: more_translucent (paired comparisons)"),
              std::string::npos);
    const std::string choices = read_file(dir / "choices.csv");
    EXPECT_EQ(std::count(choices.begin(), choices.end(), '\n'),
              1 + d.scalar_int("SELECT count(*) FROM responses"));
}

// docs/matching.md, command for command, as docs/scaling.md's: the lab session without
// the autopilot is left out, `serve` gets a free port, starts only after checking every
// picture of the series and ladders against the manifest, and serves one of each.
TEST(DocumentedMatching, ThePagesCommandsRunAsWrittenAndServeShowsEverySeries) {
    LUCENT_REQUIRE_DISPLAY();
    const std::vector<std::string> commands = page_commands("matching.md");
    ASSERT_GE(commands.size(), 8u);
    const fs::path dir = test::scratch_dir("documented_matching");
    // Each served study: the first and last picture of every series and ladder.
    const auto check_series = [&dir](const std::vector<std::string>& args,
                                     httplib::Client& client) {
        const std::string preset = *(std::find(args.begin(), args.end(), "--preset") + 1);
        const study::Protocol protocol = study::builtin_protocol(preset);
        const study::WebSeries series = study::web_series(protocol);
        for (const study::KnobSeries& k : series.series)
            for (const std::string& id : {k.pictures.front(), k.pictures.back()}) {
                const auto png =
                    client.Get(picture_url(key_file_of(args, dir), protocol, id).c_str());
                ASSERT_TRUE(png) << id;
                EXPECT_EQ(png->status, 200) << id;
                EXPECT_EQ(png->body.substr(1, 3), "PNG") << id;
            }
        // A participant agrees: their session's segment names the set of series
        // pictures it is served from (issue 44, item 6).
        const auto opened = client.Post(
            "/api/session", R"({"participant": "WEB2", "t_ms": 0})", "application/json");
        ASSERT_TRUE(opened);
        ASSERT_EQ(opened->status, 200) << opened->body;
        const nlohmann::json page = nlohmann::json::parse(opened->body);
        const nlohmann::json agree = {{"token", page["token"]},
                                      {"view", page["view"]},
                                      {"shown_ms", 10},
                                      {"t_ms", 20}};
        const auto agreed =
            client.Post("/api/continue", agree.dump(), "application/json");
        ASSERT_TRUE(agreed);
        EXPECT_EQ(agreed->status, 200) << agreed->body;
    };
    std::map<std::string, int> ran = run_page(commands, dir, check_series);
    const int served = ran["serve"];
    const bool analyzed = ran.count("analyze") > 0;
    EXPECT_EQ(served, 2);
    ASSERT_TRUE(analyzed);
    // The autopilot's 18 adjustments, each a change list ending at its final value, and
    // the report's matching section.
    study::Database d((dir / "matching.db").string(), SQLITE_OPEN_READONLY);
    EXPECT_EQ(d.scalar_int("SELECT count(*) FROM trials WHERE kind = 'adjust' AND "
                           "final_value IS NOT NULL"),
              18);
    const std::string adjustments = read_file(dir / "adjustments.csv");
    EXPECT_EQ(std::count(adjustments.begin(), adjustments.end(), '\n'),
              1 + d.scalar_int("SELECT count(*) FROM adjustments"));
    const std::string report = read_file(dir / "matching-report" / "report.md");
    EXPECT_NE(report.find("Matching"), std::string::npos) << report.substr(0, 2000);

    // Each served picture beyond the study's stimuli has its provenance row: one set per
    // folder, each picture's file and content hash as its manifest gives them.
    for (const std::string preset : {"matching", "jnd"}) {
        const study::Protocol protocol = study::builtin_protocol(preset);
        const study::Protocol shown =
            study::with_series_pictures(protocol, study::web_series(protocol));
        const std::vector<study::StimulusProvenance> expected =
            study::PrerenderedStimuli((dir / (preset + "-pictures")).string())
                .provenance(shown);
        study::Database db((dir / (preset + ".db")).string(), SQLITE_OPEN_READONLY);
        EXPECT_EQ(
            db.scalar_int("SELECT count(DISTINCT series_set) FROM session_segments"), 1)
            << preset;
        EXPECT_EQ(db.scalar_int("SELECT count(*) FROM series_pictures p JOIN "
                                "session_segments g ON g.series_set = p.set_hash"),
                  static_cast<int64_t>(shown.stimuli.size() - protocol.stimuli.size()))
            << preset;
        for (size_t i = protocol.stimuli.size(); i < expected.size(); ++i) {
            study::Statement row = db.prepare(
                "SELECT file, content_hash FROM series_pictures WHERE picture = ?");
            row.bind(1, expected[i].stimulus);
            ASSERT_TRUE(row.step()) << preset << " " << expected[i].stimulus;
            // The file as serve's --images named it (relative), the test's absolute.
            EXPECT_EQ(fs::path(row.text(0)).filename(),
                      fs::path(expected[i].file).filename())
                << expected[i].stimulus;
            EXPECT_EQ(row.text(1), expected[i].content_hash) << expected[i].stimulus;
        }
    }

    // A ladder picture missing, then one changed after it was rendered: serve refuses to
    // start, in one line naming it (and what writes it).
    const study::WebSeries jnd = study::web_series(study::builtin_protocol("jnd"));
    const study::KnobSeries& ladder = jnd.series.front();
    const fs::path pictures = dir / "jnd-pictures";
    const std::string missing = ladder.pictures[3], changed = ladder.pictures[4];
    fs::rename(pictures / (missing + ".png"), dir / "aside.png");
    const std::vector<std::string> serve{"serve",      "--preset", "jnd",          "--db",
                                         "refused.db", "--images", "jnd-pictures/"};
    Child refused;
    EXPECT_EQ(start_serve(serve, dir, refused), 0);
    EXPECT_EQ(wait_exit(refused), 2);
    EXPECT_EQ(read_file(refused.stderr_path),
              "lucent serve: preset:jnd: stimulus '" + missing +
                  "' (technique empirical): no " + missing +
                  ".png, .tif or .exr in jnd-pictures/; 'lucent render --preset jnd "
                  "--out jnd-pictures/' writes every picture the study shows in the "
                  "browser\n");
    fs::rename(dir / "aside.png", pictures / (missing + ".png"));
    fs::copy_file(pictures / (missing + ".png"), pictures / (changed + ".png"),
                  fs::copy_options::overwrite_existing);
    EXPECT_EQ(start_serve(serve, dir, refused), 0);
    EXPECT_EQ(wait_exit(refused), 2);
    const std::string why = read_file(refused.stderr_path);
    EXPECT_NE(why.find(changed + ".png: content hash "), std::string::npos) << why;
    EXPECT_NE(why.find("the image changed after it was rendered"), std::string::npos)
        << why;
    EXPECT_EQ(std::count(why.begin(), why.end(), '\n'), 1) << why;
}

}  // namespace
}  // namespace lucent
