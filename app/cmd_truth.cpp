// lucent truth: the path technique's light transport outside an image, where closed
// forms and published values can check it. `lucent truth slab` walks an infinite slab
// and prints its reflectance and transmittance with standard errors.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "app/bench_results.h"
#include "app/commands.h"
#include "renderer/techniques/path/slab.h"

namespace lucent::app {
namespace {

struct SlabArgs {
    path::SlabProblem problem;
    std::string optical_depth = "1";
    std::string incidence = "1";
    std::string csv;
    bool full = false;
};

double parse_number(const std::string& text, const std::string& flag, bool allow_inf) {
    if (allow_inf && (text == "inf" || text == "infinite")) return INFINITY;
    try {
        std::size_t used = 0;
        const double value = std::stod(text, &used);
        if (used == text.size() && std::isfinite(value)) return value;
    } catch (const std::exception&) {
    }
    throw std::invalid_argument(flag + ": '" + text + "' is not a number" +
                                (allow_inf ? " or 'inf'" : ""));
}

std::string tally_text(const path::Tally& t) {
    char text[96];
    std::snprintf(text, sizeof text, "%.5f +- %.5f", t.mean, t.standard_error);
    return text;
}

int run_slab(SlabArgs args) {
    path::SlabProblem& p = args.problem;
    try {
        p.optical_depth = parse_number(args.optical_depth, "--optical-depth", true);
        p.diffuse_incidence = args.incidence == "diffuse";
        if (!p.diffuse_incidence)
            p.incidence_cosine = parse_number(args.incidence, "--incidence", false);
        if (args.full) p.shortcuts = path::WalkShortcuts::none();
        path::check_slab_problem(p);
    } catch (const std::invalid_argument& e) {
        std::cerr << "lucent truth slab: " << e.what() << "\n";
        return kExitUsage;
    }
    std::cerr << "walking " << p.paths << " paths...\n";
    const path::SlabResult r = path::run_slab(p);
    std::cout << "slab: albedo " << p.albedo << ", g " << p.g << ", optical depth "
              << p.optical_depth << ", eta " << p.eta << ", incidence "
              << (p.diffuse_incidence ? std::string("diffuse")
                                      : "mu " + std::to_string(p.incidence_cosine))
              << ", " << p.paths << " paths (seed " << p.seed << ")\n";
    std::cout << "specular reflectance  " << tally_text(r.specular_reflectance) << "\n"
              << "diffuse reflectance   " << tally_text(r.diffuse_reflectance) << "\n"
              << "total reflectance     " << tally_text(r.total_reflectance) << "\n"
              << "total transmittance   " << tally_text(r.total_transmittance) << "\n";
    const double events = double(r.counters.scattering_events);
    std::cout << r.counters.scattering_events << " scattering events, "
              << r.counters.interface_events << " interface events, "
              << r.counters.unfinished << " walks stopped at " << p.limits.max_events
              << " events; " << r.seconds << " s ("
              << (r.seconds > 0 ? events / r.seconds : 0.0) << " events/s)\n";
    if (!args.csv.empty()) {
        BenchResults results;
        const auto add = [&](const std::string& name, const path::Tally& t) {
            results.add("slab", name, t.mean, "fraction");
            results.add("slab", name + " standard error", t.standard_error, "fraction");
        };
        add("specular reflectance", r.specular_reflectance);
        add("diffuse reflectance", r.diffuse_reflectance);
        add("total reflectance", r.total_reflectance);
        add("total transmittance", r.total_transmittance);
        results.add("slab", "scattering events", events, "count");
        results.add("slab", "unfinished walks", double(r.counters.unfinished), "count");
        results.add("slab", "time", r.seconds, "s");
        if (!results.write_csv(args.csv)) {
            std::cerr << "lucent truth slab: --csv: cannot write " << args.csv << "\n";
            return kExitFailure;
        }
    }
    return kExitOk;
}

}  // namespace

void register_truth(CLI::App& app, int& exit_code) {
    auto* truth = app.add_subcommand(
        "truth", "The path technique's light transport against closed forms: slab");
    truth->require_subcommand(1);
    auto args = std::make_shared<SlabArgs>();
    auto* slab = truth->add_subcommand(
        "slab",
        "Total diffuse reflectance and transmittance of an infinite slab lit from above, "
        "with standard errors, by the path technique's walk");
    slab->add_option("--albedo", args->problem.albedo, "sigma_s / sigma_t, in [0, 1]")
        ->capture_default_str();
    slab->add_option("--g", args->problem.g, "Henyey-Greenstein asymmetry, in (-1, 1)")
        ->capture_default_str();
    slab->add_option("--optical-depth", args->optical_depth,
                     "sigma_t times the thickness, or inf (semi-infinite)")
        ->capture_default_str();
    slab->add_option("--eta", args->problem.eta,
                     "the slab's index relative to the outside (1: index-matched)")
        ->capture_default_str();
    slab->add_option("--incidence", args->incidence,
                     "cosine of the collimated beam's angle to the normal, or diffuse")
        ->capture_default_str();
    slab->add_option("--paths", args->problem.paths, "paths to walk")
        ->capture_default_str();
    slab->add_option("--seed", args->problem.seed, "random seed")->capture_default_str();
    slab->add_flag(
        "--full", args->full,
        "take none of the walk's shortcuts (eta = 1 without Fresnel events, no "
        "collisions without scattering)");
    slab->add_option("--csv", args->csv, "also write the numbers to FILE");
    slab->callback([args, &exit_code] { exit_code = run_slab(*args); });
}

}  // namespace lucent::app
