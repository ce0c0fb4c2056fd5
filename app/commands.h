#pragma once
// Each subcommand lives in its own cmd_<name>.cpp and registers itself here; main.cpp
// only lists them. A subcommand's callback returns the process exit code through
// `exit_code`.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <string>

namespace lucent::app {

// Exit codes shared by every subcommand.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;  // the work itself failed (GL, I/O, ...)
inline constexpr int kExitUsage = 2;    // bad command line, config or input data

void register_info(CLI::App& app, int& exit_code);
void register_bench(CLI::App& app, int& exit_code);
void register_analyze(CLI::App& app, int& exit_code);
void register_stats(CLI::App& app, int& exit_code);
void register_simulate(CLI::App& app, int& exit_code);
void register_power(CLI::App& app, int& exit_code);
void register_render(CLI::App& app, int& exit_code);
void register_run(CLI::App& app, int& exit_code);
void register_serve(CLI::App& app, int& exit_code);
void register_participants(CLI::App& app, int& exit_code);
void register_export(CLI::App& app, int& exit_code);
void register_merge(CLI::App& app, int& exit_code);
void register_explore(CLI::App& app, int& exit_code);
void register_store(CLI::App& app, int& exit_code);
void register_stimuli(CLI::App& app, int& exit_code);
void register_truth(CLI::App& app, int& exit_code);

// `lucent analyze --images`: how a level's picture becomes a thumbnail (PNG bytes).
// lucent-full sets it (it links the image library); unset, the picture itself is
// embedded.
using ThumbnailMaker = std::string (*)(const std::filesystem::path& picture);
void set_analyze_thumbnail_maker(ThumbnailMaker maker);

// `lucent bench <family>`: registered from bench_families.cpp, one function per family.
void register_bench_families(CLI::App& bench, int& exit_code);
void register_bench_frame(CLI::App& bench, int& exit_code);
void register_bench_accuracy(CLI::App& bench, int& exit_code);
void register_bench_ao(CLI::App& bench, int& exit_code);
void register_bench_stats(CLI::App& bench, int& exit_code);
void register_bench_render(CLI::App& bench, int& exit_code);
void register_bench_store(CLI::App& bench, int& exit_code);
void register_bench_fidelity(CLI::App& bench, int& exit_code);
void register_bench_truth(CLI::App& bench, int& exit_code);

}  // namespace lucent::app
