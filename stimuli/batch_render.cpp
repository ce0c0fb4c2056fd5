// Batch rendering: load meshes, decide what changed, render on N workers (one GL context
// each), write images + manifest, show progress.
// [SECTION] manifest rows: identity, parameter columns, file hashes, reuse decision
// [SECTION] BatchProgress: stimuli done, time per stimulus, time left
// [SECTION] render_stimulus_set(): meshes, reuse, AO pre-bake, workers, manifest
// [SECTION] run_render_set_command(): the CLI's batch path and its exit codes
#include "stimuli/batch_render.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "common/content_hash.h"
#include "lucent/version.h"
#include "renderer/core/mesh.h"
#include "renderer/core/technique.h"
#include "renderer/gl/context.h"
#include "renderer/render.h"
#include "renderer/techniques/registry.h"
#include "stimuli/set_report/set_report.h"

namespace lucent::stimuli {
namespace {

using Clock = std::chrono::steady_clock;
constexpr int kHistogramBins = 16;  // manifest columns hist_00 .. hist_15
double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

std::filesystem::path file_of(const Stimulus& s, ImageFormat format) {
    return s.id + "." + std::string(extension(format));
}

// The parameter columns in knob order (scene knobs first), values as text.
std::vector<ManifestField> parameter_fields(const Stimulus& stimulus) {
    std::vector<ManifestField> fields;
    for (const Knob& knob : knobs_for(find_technique(stimulus.technique))) {
        const auto& value = stimulus.parameters.get(knob.name);
        const bool numeric =
            std::holds_alternative<double>(value) || std::holds_alternative<int>(value);
        fields.push_back({knob.name, format_knob_value(value), numeric});
        // An input's content hash follows its spec, as mesh_hash follows mesh.
        if (knob.input_hash)
            fields.push_back(
                {input_hash_column(knob), knob.input_hash(stimulus.parameters), false});
    }
    return fields;
}

// Every parameter name of the set's techniques, in knob order (scene knobs first), so
// all rows list the parameters in the same columns.
std::vector<std::string> parameter_columns(const StimulusSet& set) {
    std::vector<std::string> columns;
    for (const auto& s : set.stimuli)
        for (const Knob& knob : knobs_for(find_technique(s.technique)))
            if (std::find(columns.begin(), columns.end(), knob.name) == columns.end()) {
                columns.push_back(knob.name);
                if (knob.input_hash) columns.push_back(input_hash_column(knob));
            }
    return columns;
}

// The identity part of a row (before statistics and hashes); parameters the stimulus's
// technique lacks are empty.
ManifestRow identity_fields(const StimulusSet& set, const Stimulus& s, const Mesh& mesh) {
    std::string files;
    for (const auto format : set.formats)
        files += (files.empty() ? "" : ";") + file_of(s, format).string();
    ManifestRow row = {{"id", s.id, false},
                       {"file", file_of(s, set.formats.front()).string(), false},
                       {"files", files, false},
                       {"technique", s.technique, false},
                       {"series", s.series, false},
                       {"mesh", s.mesh_spec, false},
                       {"mesh_faces", std::to_string(mesh.face_count()), true},
                       {"mesh_hash", mesh.content_hash, false},
                       {"width", std::to_string(set.width), true},
                       {"height", std::to_string(set.height), true}};
    const auto parameters = parameter_fields(s);
    for (const auto& column : parameter_columns(set)) {
        ManifestField field{column, "", false};
        for (const auto& p : parameters)
            if (p.column == column) field = p;
        row.push_back(field);
    }
    return row;
}

std::string files_hash(const std::filesystem::path& dir, const StimulusSet& set,
                       const Stimulus& s) {
    common::ContentHash hasher;
    for (const auto format : set.formats)
        hasher.field(common::hash_file(dir / file_of(s, format)));
    return hasher.hex();
}

// A non-negative integer cell, e.g. a count; nullopt when the text is anything else.
std::optional<std::size_t> parse_count(const std::string& text) {
    std::size_t value = 0;
    const auto [end, error] =
        std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size() || text.empty())
        return std::nullopt;
    return value;
}

// The content hash of the previous run's files for `s` when they are present, unchanged
// and made from the same inputs (the stimulus is then reused); empty otherwise.
std::string reusable_content_hash(const std::map<std::string, std::string>* previous,
                                  const std::string& inputs,
                                  const std::filesystem::path& dir,
                                  const StimulusSet& set, const Stimulus& s) {
    if (!previous) return {};
    const auto field = [&](const char* column) {
        const auto it = previous->find(column);
        return it == previous->end() ? std::string() : it->second;
    };
    if (field("input_hash") != inputs || !parse_count(field("non_finite_pixels")))
        return {};
    for (const auto format : set.formats) {
        std::error_code error;
        if (!std::filesystem::is_regular_file(dir / file_of(s, format), error)) return {};
    }
    try {
        const std::string content = files_hash(dir, set, s);
        return content == field("content_hash") ? content : std::string();
    } catch (const std::exception&) {
        return {};
    }
}

// The columns measured on a rendered image: statistics, then the count of pixels that
// had NaN or Inf values (replaced before writing; non-zero means a rendering bug).
std::vector<ManifestField> measured_fields(const ImageStatistics& stats,
                                           std::size_t non_finite_pixels) {
    auto fields = statistics_fields(stats);
    fields.push_back({"non_finite_pixels", std::to_string(non_finite_pixels), true});
    return fields;
}

// The columns every row ends with: software, inputs and the files' content hash.
void append_provenance(ManifestRow& row, const std::string& inputs,
                       const std::string& content) {
    row.push_back({"software_version", version_string(), false});
    row.push_back({"build_hash", build_hash(), false});
    row.push_back({"input_hash", inputs, false});
    row.push_back({"content_hash", content, false});
}

// Writes the complete rows (non-empty; in set order) as the manifest, atomically. Called
// before any file is replaced and after each stimulus, so an interrupted run leaves a
// manifest that describes exactly the files it lists, and the next run resumes.
void write_complete_rows(const std::filesystem::path& dir, const StimulusSet& set,
                         const std::vector<ManifestRow>& rows) {
    std::vector<ManifestRow> complete;
    for (const auto& row : rows)
        if (!row.empty()) complete.push_back(row);
    write_manifest(dir, set.name, complete);
}

// A one-line progress display: stimuli done, time per stimulus, time left. Redrawn in
// place on a terminal; one line per stimulus otherwise (logs).
class BatchProgress {
public:
    BatchProgress(std::size_t total, bool enabled)
        : total_(total),
          enabled_(enabled && total > 0),
          tty_(isatty(STDERR_FILENO)),
          start_(Clock::now()) {}
    void done(std::size_t finished, const std::string& id) {
        if (!enabled_) return;
        const double elapsed = seconds_since(start_);
        const double per = elapsed / double(std::max<std::size_t>(finished, 1));
        const double left = per * double(total_ - finished);
        const int width = 24,
                  filled = int(double(width) * double(finished) / double(total_));
        std::string bar(std::size_t(filled), '#');
        bar.resize(std::size_t(width), '.');
        std::fprintf(stderr, "%s[%s] %zu/%zu stimuli  %.2f s/stimulus  %.1f s left  %s%s",
                     tty_ ? "\r" : "", bar.c_str(), finished, total_, per, left,
                     id.c_str(), tty_ ? "\033[K" : "\n");
        if (tty_ && finished == total_) std::fprintf(stderr, "\n");
        std::fflush(stderr);
    }

private:
    std::size_t total_;
    bool enabled_, tty_;
    Clock::time_point start_;
};

}  // namespace

std::string input_hash(const StimulusSet& set, const Stimulus& stimulus,
                       const std::string& mesh_hash) {
    common::ContentHash hasher;
    hasher.field(version_string()).field(build_hash());
    hasher.field(stimulus.technique).field(mesh_hash);
    hasher.field(std::to_string(set.width)).field(std::to_string(set.height));
    for (const auto format : set.formats) hasher.field(extension(format));
    for (const auto& [name, value] : stimulus.parameters.all())
        hasher.field(name).field(format_knob_value(value));
    // An input file can change under the same spec: its content decides.
    for (const auto& [column, hash] :
         input_hashes(knobs_for(find_technique(stimulus.technique)), stimulus.parameters))
        hasher.field(column).field(hash);
    return hasher.hex();
}

BatchResult render_stimulus_set(const StimulusSet& set, const BatchOptions& options) {
    const auto wall_start = Clock::now();
    const auto& dir = options.out_dir;
    BatchResult result;

    // Meshes, once per spec (MeshError propagates before anything is written).
    std::map<std::string, std::shared_ptr<const Mesh>> meshes;
    for (const auto& s : set.stimuli)
        if (!meshes.count(s.mesh_spec))
            meshes[s.mesh_spec] = std::make_shared<const Mesh>(load_mesh(s.mesh_spec));

    std::filesystem::create_directories(dir);
    const auto previous = read_manifest_csv(dir);

    // Decide what to render; reused rows keep the previous run's measurements verbatim.
    const std::size_t count = set.stimuli.size();
    std::vector<ManifestRow> rows(count);  // empty until the stimulus is complete
    std::vector<std::string> inputs(count);
    std::vector<std::size_t> pending;
    for (std::size_t i = 0; i < count; ++i) {
        const auto& s = set.stimuli[i];
        const Mesh& mesh = *meshes.at(s.mesh_spec);
        inputs[i] = input_hash(set, s, mesh.content_hash);
        const auto it = previous.find(s.id);
        const auto* old = it == previous.end() ? nullptr : &it->second;
        const std::string content =
            options.force ? std::string()
                          : reusable_content_hash(old, inputs[i], dir, set, s);
        if (!content.empty()) {
            rows[i] = identity_fields(set, s, mesh);
            ImageStatistics columns;
            columns.luminance_histogram.resize(kHistogramBins);
            for (const auto& field : measured_fields(columns, 0)) {
                const auto found = old->find(field.column);
                rows[i].push_back(
                    {field.column, found == old->end() ? "0" : found->second, true});
            }
            append_provenance(rows[i], inputs[i], content);
            ++result.reused;
        } else {
            pending.push_back(i);
        }
    }
    // Drop the rows of everything about to be re-rendered before any file is replaced.
    write_complete_rows(dir, set, rows);

    // Produce the bakes (ProductionCost::bake uploads: the AO) the pending plans upload
    // once each, here, by content hash, so parallel workers never bake the same data
    // twice and a bake's own progress bar is not interleaved; workers are handed the
    // results (see render_worker).
    double prebake_seconds = 0.0;
    std::map<std::string, TextureData> baked;  // read-only once the workers start
    {
        std::map<std::string, Pass> bakes;
        for (const std::size_t i : pending) {
            const Stimulus& s = set.stimuli[i];
            const Technique& technique = find_technique(s.technique);
            const Scene scene = make_scene(meshes.at(s.mesh_spec), technique,
                                           s.parameters, set.width, set.height);
            for (const Pass& pass : make_frame_plan(scene, technique).passes)
                if (is_bake(pass)) bakes.emplace(pass.data.content_hash, pass);
        }
        const auto start = Clock::now();
        for (const auto& [hash, pass] : bakes) baked.emplace(hash, produce_upload(pass));
        prebake_seconds = seconds_since(start);
    }

    // Render the pending stimuli on `jobs` render workers, each with its own GL context,
    // and encode them on `jobs` encode workers, so files are written while the next
    // image renders. A bounded queue between them holds at most `jobs` images. The first
    // failure anywhere (GL, I/O, after_stimulus) stops both sides: rendered but not yet
    // encoded images are dropped, so the manifest lists only finished stimuli.
    struct RenderedStimulus {
        std::size_t index;  // into set.stimuli
        RenderedImage rendered;
    };
    std::mutex mutex;  // guards everything below and the manifest rows
    std::condition_variable finished_signal, queue_changed;
    std::size_t finished = 0;
    std::atomic<std::size_t> next{0};
    std::string failure;
    std::vector<std::string> finished_ids;
    std::deque<RenderedStimulus> queue;
    const int jobs =
        std::clamp(options.jobs, 1, int(std::max<std::size_t>(pending.size(), 1)));
    int rendering = jobs;  // render workers still running; 0 closes the queue
    std::vector<BatchTimings> render_timings(static_cast<std::size_t>(jobs)),
        encode_timings(static_cast<std::size_t>(jobs));
    const auto fail = [&](const std::string& what) {  // caller holds `mutex`
        if (failure.empty()) failure = what;
        finished_signal.notify_all();
        queue_changed.notify_all();
    };

    // Files, statistics and the manifest row of one rendered stimulus; false when the run
    // has stopped meanwhile (the row is then not written). Throws on I/O failure.
    const auto finish_stimulus = [&](const RenderedStimulus& item,
                                     BatchTimings& timings) {
        const std::size_t i = item.index;
        const Stimulus& s = set.stimuli[i];
        const Image& image = item.rendered.image;

        auto start = Clock::now();
        for (const auto format : set.formats)
            write_image(dir / file_of(s, format), image, {.png = options.png});
        timings.encode_seconds += seconds_since(start);

        start = Clock::now();
        ManifestRow row = identity_fields(set, s, *meshes.at(s.mesh_spec));
        const auto stats = compute_image_statistics(
            FloatImageView{image.width, image.height, 4, image.rgba}, kHistogramBins);
        const auto measured = measured_fields(stats, item.rendered.non_finite_pixels);
        row.insert(row.end(), measured.begin(), measured.end());
        append_provenance(row, inputs[i], files_hash(dir, set, s));
        timings.statistics_seconds += seconds_since(start);

        std::size_t done = 0;
        {
            std::lock_guard lock(mutex);
            if (!failure.empty()) return false;  // another worker failed meanwhile
            rows[i] = std::move(row);
            write_complete_rows(dir, set, rows);
            finished_ids.push_back(s.id);
            done = ++finished;
            finished_signal.notify_one();
        }
        if (options.after_stimulus) options.after_stimulus(s.id, done);
        return true;
    };

    auto render_worker = [&](int index) {
        BatchTimings& timings = render_timings[std::size_t(index)];
        try {
            auto context = gl::create_headless_context();
            gl::FrameExecutor executor;
            // Bakes come from the pre-bake above; their time (and that of any bake it
            // missed) counts as bake time, not GL time.
            executor.set_upload_producer([&timings, &baked](const Pass& pass) {
                if (!is_bake(pass)) return produce_upload(pass);
                const auto start = Clock::now();
                const auto it = baked.find(pass.data.content_hash);
                TextureData data = it != baked.end() ? it->second : produce_upload(pass);
                timings.ao_seconds += seconds_since(start);
                return data;
            });
            for (std::size_t k; (k = next++) < pending.size();) {
                {
                    std::lock_guard lock(mutex);
                    if (!failure.empty()) break;
                }
                const std::size_t i = pending[k];
                const Stimulus& s = set.stimuli[i];
                const Technique& technique = find_technique(s.technique);

                // The single-image path of `lucent render --mesh`.
                const auto start = Clock::now();
                const double ao_before = timings.ao_seconds;
                const Scene scene = make_scene(meshes.at(s.mesh_spec), technique,
                                               s.parameters, set.width, set.height);
                RenderedStimulus item{i, render_image_counted(executor, scene)};
                timings.gl_seconds +=
                    seconds_since(start) - (timings.ao_seconds - ao_before);

                if (!options.overlap_encode) {  // encode here, before the next render
                    if (!finish_stimulus(item, timings)) break;
                    continue;
                }
                std::unique_lock lock(mutex);
                queue_changed.wait(lock, [&] {
                    return queue.size() < std::size_t(jobs) || !failure.empty();
                });
                if (!failure.empty()) break;
                queue.push_back(std::move(item));
                queue_changed.notify_all();
            }
        } catch (const std::exception& e) {
            std::lock_guard lock(mutex);
            fail(e.what());
        }
        std::lock_guard lock(mutex);
        --rendering;
        queue_changed.notify_all();
    };

    auto encode_worker = [&](int index) {
        BatchTimings& timings = encode_timings[std::size_t(index)];
        try {
            for (;;) {
                std::optional<RenderedStimulus> item;
                {
                    std::unique_lock lock(mutex);
                    queue_changed.wait(lock, [&] {
                        return !queue.empty() || rendering == 0 || !failure.empty();
                    });
                    if (!failure.empty() || queue.empty()) return;
                    item = std::move(queue.front());
                    queue.pop_front();
                    queue_changed.notify_all();
                }
                if (!finish_stimulus(*item, timings)) return;
            }
        } catch (const std::exception& e) {
            std::lock_guard lock(mutex);
            fail(e.what());
        }
    };
    std::vector<std::thread> workers;
    for (int w = 0; w < jobs && !pending.empty(); ++w) {
        workers.emplace_back(render_worker, w);
        if (options.overlap_encode) workers.emplace_back(encode_worker, w);
    }

    BatchProgress progress(pending.size(), options.progress);
    {
        std::unique_lock lock(mutex);
        std::size_t shown = 0;
        while (shown < pending.size() && failure.empty()) {
            finished_signal.wait(lock,
                                 [&] { return finished > shown || !failure.empty(); });
            while (shown < finished) {
                const std::string id = finished_ids[shown++];
                lock.unlock();
                progress.done(shown, id);
                lock.lock();
            }
        }
    }
    for (auto& thread : workers) thread.join();
    if (!failure.empty()) throw std::runtime_error(failure);
    result.rendered = pending.size();

    for (std::size_t i = 0; i < count; ++i) {
        const auto& row = rows[i];
        const auto it = std::find_if(row.begin(), row.end(), [](const ManifestField& f) {
            return f.column == "non_finite_pixels";
        });
        const auto pixels = it == row.end() ? std::nullopt : parse_count(it->text);
        if (pixels && *pixels > 0)
            result.non_finite.push_back({set.stimuli[i].id, *pixels});
    }
    result.rows = std::move(rows);
    result.timings.ao_seconds = prebake_seconds;
    for (const auto* timings : {&render_timings, &encode_timings})
        for (const auto& t : *timings) {
            result.timings.ao_seconds += t.ao_seconds;
            result.timings.gl_seconds += t.gl_seconds;
            result.timings.encode_seconds += t.encode_seconds;
            result.timings.statistics_seconds += t.statistics_seconds;
        }
    result.timings.wall_seconds = seconds_since(wall_start);
    return result;
}

int run_render_set_command(const std::string& config_path, const std::string& preset,
                           const std::string& out_dir, int jobs, bool force) {
    StimulusSet set;
    try {
        if (out_dir.empty()) throw StimulusSetError("--out: missing (give --out DIR)");
        if (jobs < 1 || jobs > 64)
            throw StimulusSetError("--jobs: " + std::to_string(jobs) +
                                   " is out of range (accepted: 1..64)");
        const auto catalog = default_catalog();
        set = preset.empty() ? load_stimulus_set(config_path, catalog)
                             : load_preset(preset, catalog);
        std::error_code error;
        if (std::filesystem::exists(out_dir, error) &&
            !std::filesystem::is_directory(out_dir, error))
            throw StimulusSetError("--out: '" + out_dir +
                                   "' exists and is not a directory");
    } catch (const StimulusSetError& e) {
        std::cerr << "lucent render: " << e.what() << "\n";
        return 2;
    }
    try {
        BatchOptions options;
        options.out_dir = out_dir;
        options.jobs = jobs;
        options.force = force;
        const BatchResult result = render_stimulus_set(set, options);
        std::cout << "rendered " << result.rendered << ", unchanged " << result.reused
                  << " of " << set.stimuli.size() << " stimuli into " << out_dir
                  << " (manifest.csv, manifest.json) in " << result.timings.wall_seconds
                  << " s\n";
        for (const auto& [id, pixels] : result.non_finite)
            std::cerr << "lucent render: warning: stimulus '" << id << "': " << pixels
                      << " pixels had NaN or Inf values (written as 0 or the largest "
                         "float; manifest column non_finite_pixels)\n";
        if (!result.non_finite.empty()) return 1;
    } catch (const MeshError& e) {
        std::cerr << "lucent render: " << set.source << ": mesh " << e.what() << "\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "lucent render: " << e.what() << "\n";
        return 1;
    }
    // The complete set's report (report.html, contact-sheet.png), as `lucent stimuli
    // report DIR` writes it; a set that cannot be reported is a failure of the run.
    return run_stimuli_report(out_dir, {}, "lucent render") == 0 ? 0 : 1;
}

}  // namespace lucent::stimuli
