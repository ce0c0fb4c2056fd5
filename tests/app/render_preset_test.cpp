// One preset name, one meaning (issue 44 item 9): `lucent render --preset NAME --out DIR`
// writes every picture `lucent run|serve --preset NAME --images DIR` shows, a built-in
// study's adjust series and staircase ladders included, so serve's picture check (every
// picture present and as its manifest describes it) passes on DIR. Runs the real binary.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "study/protocol.h"
#include "study/session/stimulus_source.h"
#include "study/web_series.h"
#include "tests/support/test_paths.h"

namespace lucent {
namespace {

namespace fs = std::filesystem;

std::string read_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

struct Ran {
    int code = -1;
    std::string out, err;
};

// `lucent ARGS` with its stdout and stderr in files of `dir`.
Ran lucent(const std::string& args, const fs::path& dir) {
    const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
    const std::string command = std::string("'") + LUCENT_EXECUTABLE + "' " + args +
                                " >'" + out.string() + "' 2>'" + err.string() + "'";
    const int status = std::system(command.c_str());
    Ran ran;
    ran.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    ran.out = read_file(out);
    ran.err = read_file(err);
    return ran;
}

// The jnd study's 3 standards and their ladders (57 pictures at 256x256, a few seconds).
TEST(RenderPreset, ABuiltInStudysFolderPassesServesPictureCheck) {
    const fs::path dir = test::scratch_dir("render_preset");
    const fs::path pictures = dir / "jnd-pictures";
    const Ran render =
        lucent("render --preset jnd --out '" + pictures.string() + "'", dir);
    ASSERT_EQ(render.code, 0) << render.err;

    // What `lucent serve --preset jnd --images DIR` checks before it starts.
    const study::Protocol protocol = study::builtin_protocol("jnd");
    const study::WebSeries series = study::web_series(protocol);
    ASSERT_FALSE(series.added.empty());
    const study::Protocol shown = study::with_series_pictures(protocol, series);
    const study::PrerenderedStimuli stimuli(pictures.string());
    EXPECT_NO_THROW(stimuli.check(shown));
    std::vector<study::StimulusProvenance> checked;
    try {
        checked = stimuli.provenance(shown);  // each against the manifest
    } catch (const std::exception& e) {
        FAIL() << e.what();
    }
    ASSERT_EQ(checked.size(), shown.stimuli.size());
    for (const study::StimulusProvenance& p : checked) {
        EXPECT_EQ(p.source, "images") << p.stimulus;
        EXPECT_FALSE(p.content_hash.empty()) << p.stimulus;
    }
    EXPECT_NE(render.out.find("rendered " + std::to_string(shown.stimuli.size()) + ", "),
              std::string::npos)
        << render.out;
    // The set's own factor series stays for its report: the standards are one series.
    EXPECT_NE(read_file(pictures / "manifest.csv")
                  .find("\nr_18,r_18.png,r_18.png,empirical,thickness_exponent,"),
              std::string::npos);

    // The old flag is the same set: nothing to render again.
    const Ran again =
        lucent("render --study-preset jnd --out '" + pictures.string() + "'", dir);
    ASSERT_EQ(again.code, 0) << again.err;
    EXPECT_NE(again.out.find("rendered 0, unchanged " +
                             std::to_string(shown.stimuli.size()) + " of "),
              std::string::npos)
        << again.out;
}

// Every built-in study's stimulus set agrees with the study on each picture both name
// (else the folder would hold another render than the study checks): the set is made,
// series and all, and only the --out that is a file stops it, before anything renders.
TEST(RenderPreset, EveryBuiltInStudysSetAgreesWithItsStudy) {
    const fs::path dir = test::scratch_dir("render_preset");
    const fs::path file = dir / "a-file";
    std::ofstream(file) << "not a folder\n";
    for (const std::string& name : study::builtin_protocol_names()) {
        const Ran ran =
            lucent("render --preset " + name + " --out '" + file.string() + "'", dir);
        EXPECT_EQ(ran.code, 2) << name;
        EXPECT_EQ(ran.err, "lucent render: --out: '" + file.string() +
                               "' exists and is not a directory\n")
            << name;
    }
}

}  // namespace
}  // namespace lucent
