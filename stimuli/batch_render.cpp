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
    return s.id + "." + std::string(image_extension(format));
}

// The parameter columns in knob order (scene knobs first), values as text.
std::vector<ManifestField> parameter_fields(const Stimulus& stimulus) {
    std::vector<ManifestField> fields;
    for (const Knob& knob : knobs_for(find_technique(stimulus.technique))) {
        const auto& value = stimulus.values.get(knob.name);
        const bool numeric =
            std::holds_alternative<double>(value) || std::holds_alternative<int>(value);
        fields.push_back({knob.name, format_knob_value(value), numeric});
        // An input's content hash follows its spec, as mesh_hash follows mesh.
        if (knob.input_hash)
            fields.push_back(
                {input_hash_column(knob), knob.input_hash(stimulus.values), false});
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
                       {"mesh", s.mesh, false},
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
    for (const auto format : set.formats) hasher.field(image_extension(format));
    for (const auto& [name, value] : stimulus.values.all())
        hasher.field(name).field(format_knob_value(value));
    // An input file can change under the same spec: its content decides.
    for (const auto& [column, hash] :
         input_hashes(knobs_for(find_technique(stimulus.technique)), stimulus.values))
        hasher.field(column).field(hash);
    return hasher.hex();
}

namespace {

using MeshesBySpec = std::map<std::string, std::shared_ptr<const Mesh>>;

// Meshes, once per spec (MeshError propagates before anything is written).
MeshesBySpec load_meshes(const StimulusSet& set) {
    MeshesBySpec meshes;
    for (const auto& s : set.stimuli)
        if (!meshes.count(s.mesh))
            meshes[s.mesh] = std::make_shared<const Mesh>(load_mesh(s.mesh));
    return meshes;
}

// What this run renders, and the rows it keeps from the previous run.
struct RenderPlan {
    std::vector<ManifestRow> rows;     // empty until the stimulus is complete
    std::vector<std::string> inputs;   // input_hash() of each stimulus, in set order
    std::vector<std::size_t> pending;  // the stimuli to render (indices into set.stimuli)
    std::size_t reused = 0;
};

// The row of a reused stimulus, with the previous run's measurements (`old`) verbatim.
ManifestRow reused_row(const StimulusSet& set, const Stimulus& s, const Mesh& mesh,
                       const std::map<std::string, std::string>& old,
                       const std::string& inputs, const std::string& content) {
    ManifestRow row = identity_fields(set, s, mesh);
    ImageStatistics columns;
    columns.luminance_histogram.resize(kHistogramBins);
    for (const auto& field : measured_fields(columns, 0)) {
        const auto found = old.find(field.column);
        row.push_back({field.column, found == old.end() ? "0" : found->second, true});
    }
    append_provenance(row, inputs, content);
    return row;
}

// Decide what to render; reused rows keep the previous run's measurements verbatim.
RenderPlan plan_renders(
    const StimulusSet& set, const BatchOptions& options, const MeshesBySpec& meshes,
    const std::map<std::string, std::map<std::string, std::string>>& previous) {
    const auto& dir = options.out_dir;
    const std::size_t count = set.stimuli.size();
    RenderPlan plan;
    plan.rows.resize(count);
    plan.inputs.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
        const auto& s = set.stimuli[i];
        const Mesh& mesh = *meshes.at(s.mesh);
        plan.inputs[i] = input_hash(set, s, mesh.content_hash);
        const auto it = previous.find(s.id);
        const auto* old = it == previous.end() ? nullptr : &it->second;
        const std::string content =
            options.force ? std::string()
                          : reusable_content_hash(old, plan.inputs[i], dir, set, s);
        if (!content.empty()) {
            plan.rows[i] = reused_row(set, s, mesh, *old, plan.inputs[i], content);
            ++plan.reused;
        } else {
            plan.pending.push_back(i);
        }
    }
    return plan;
}

// The pre-bake's results, by content hash, and the time it took.
struct Prebaked {
    std::map<std::string, TextureData> by_hash;  // read-only once the workers start
    double seconds = 0.0;
};

// Produce the bakes (ProductionCost::bake uploads: the AO) the pending plans upload
// once each, here, by content hash, so parallel workers never bake the same data
// twice and a bake's own progress bar is not interleaved; workers are handed the
// results (see RenderWorkers::render_worker).
Prebaked prebake(const StimulusSet& set, const MeshesBySpec& meshes,
                 const std::vector<std::size_t>& pending, bool show_progress) {
    Prebaked baked;
    std::map<std::string, Pass> bakes;
    for (const std::size_t i : pending) {
        const Stimulus& s = set.stimuli[i];
        const Technique& technique = find_technique(s.technique);
        const Scene scene =
            make_scene(meshes.at(s.mesh), technique, s.values, set.width, set.height);
        for (const Pass& pass : make_frame_plan(scene, technique).passes)
            if (is_bake(pass)) bakes.emplace(pass.data.content_hash, pass);
    }
    const auto start = Clock::now();
    // A bake may take minutes (a path-traced picture): each says what it is, reports its
    // own progress where it can (done / total) and its time when finished.
    const bool tty = isatty(STDERR_FILENO);
    std::size_t number = 0;
    for (const auto& [hash, pass] : bakes) {
        ++number;
        const auto bake_start = Clock::now();
        ProduceOptions produce;
        if (show_progress)
            produce.progress = [&](std::size_t done, std::size_t total) {
                if (!tty && done != total) return;
                std::fprintf(stderr, "%sbake %zu/%zu %s: %zu/%zu, %.1f s%s",
                             tty ? "\r" : "", number, bakes.size(), pass.name.c_str(),
                             done, total, seconds_since(bake_start),
                             tty ? "\033[K" : "\n");
                std::fflush(stderr);
            };
        baked.by_hash.emplace(hash, pass.data.produce(produce));
        if (show_progress && tty) std::fprintf(stderr, "\n");
    }
    baked.seconds = seconds_since(start);
    return baked;
}

// An image rendered and not yet encoded.
struct RenderedStimulus {
    std::size_t index;  // into set.stimuli
    RenderedImage rendered;
};

// Render the pending stimuli on `jobs` render workers, each with its own GL context,
// and encode them on `jobs` encode workers, so files are written while the next
// image renders. A bounded queue between them holds at most `jobs` images. The first
// failure anywhere (GL, I/O, after_stimulus) stops both sides: rendered but not yet
// encoded images are dropped, so the manifest lists only finished stimuli.
class RenderWorkers {
public:
    // Renders plan.pending and fills plan.rows; everything passed must outlive this.
    RenderWorkers(const StimulusSet& set, const BatchOptions& options,
                  const MeshesBySpec& meshes,
                  const std::map<std::string, TextureData>& baked, RenderPlan& plan)
        : set_(set),
          options_(options),
          meshes_(meshes),
          baked_(baked),
          rows_(plan.rows),
          inputs_(plan.inputs),
          pending_(plan.pending),
          jobs_(std::clamp(options.jobs, 1,
                           int(std::max<std::size_t>(pending_.size(), 1)))),
          rendering_(jobs_),
          render_timings_(static_cast<std::size_t>(jobs_)),
          encode_timings_(static_cast<std::size_t>(jobs_)) {}

    // Starts the workers, shows progress until every pending stimulus is finished or one
    // failed, and joins them; throws std::runtime_error with the first failure.
    void run();
    const std::vector<BatchTimings>& render_timings() const { return render_timings_; }
    const std::vector<BatchTimings>& encode_timings() const { return encode_timings_; }

private:
    void fail(const std::string& what);
    bool finish_stimulus(const RenderedStimulus& item, BatchTimings& timings);
    void render_worker(int index);
    void encode_worker(int index);
    void show_progress();

    const StimulusSet& set_;
    const BatchOptions& options_;
    const MeshesBySpec& meshes_;
    const std::map<std::string, TextureData>& baked_;
    std::vector<ManifestRow>& rows_;
    const std::vector<std::string>& inputs_;
    const std::vector<std::size_t>& pending_;
    const int jobs_;
    std::mutex mutex_;  // guards everything below and the manifest rows
    std::condition_variable finished_signal_, queue_changed_;
    std::size_t finished_ = 0;
    std::atomic<std::size_t> next_{0};
    std::string failure_;
    std::vector<std::string> finished_ids_;
    std::deque<RenderedStimulus> queue_;
    int rendering_;  // render workers still running; 0 closes the queue
    std::vector<BatchTimings> render_timings_, encode_timings_;
};

void RenderWorkers::fail(const std::string& what) {  // caller holds `mutex_`
    if (failure_.empty()) failure_ = what;
    finished_signal_.notify_all();
    queue_changed_.notify_all();
}

// Files, statistics and the manifest row of one rendered stimulus; false when the run
// has stopped meanwhile (the row is then not written). Throws on I/O failure.
bool RenderWorkers::finish_stimulus(const RenderedStimulus& item, BatchTimings& timings) {
    const auto& dir = options_.out_dir;
    const std::size_t i = item.index;
    const Stimulus& s = set_.stimuli[i];
    const Image& image = item.rendered.image;

    auto start = Clock::now();
    for (const auto format : set_.formats)
        write_image(dir / file_of(s, format), image, {.png = options_.png});
    timings.encode_seconds += seconds_since(start);

    start = Clock::now();
    ManifestRow row = identity_fields(set_, s, *meshes_.at(s.mesh));
    const auto stats = compute_image_statistics(
        FloatImageView{image.width, image.height, 4, image.rgba}, kHistogramBins);
    const auto measured = measured_fields(stats, item.rendered.non_finite_pixels);
    row.insert(row.end(), measured.begin(), measured.end());
    append_provenance(row, inputs_[i], files_hash(dir, set_, s));
    timings.statistics_seconds += seconds_since(start);

    std::size_t done = 0;
    {
        std::lock_guard lock(mutex_);
        if (!failure_.empty()) return false;  // another worker failed meanwhile
        rows_[i] = std::move(row);
        write_complete_rows(dir, set_, rows_);
        finished_ids_.push_back(s.id);
        done = ++finished_;
        finished_signal_.notify_one();
    }
    if (options_.after_stimulus) options_.after_stimulus(s.id, done);
    return true;
}

void RenderWorkers::render_worker(int index) {
    BatchTimings& timings = render_timings_[std::size_t(index)];
    try {
        auto context = gl::create_headless_context();
        gl::FrameExecutor executor;
        // Bakes come from the pre-bake (prebake()); their time (and that of any bake it
        // missed) counts as bake time, not GL time.
        executor.set_upload_producer([&timings, &baked = baked_](const Pass& pass) {
            if (!is_bake(pass)) return produce_upload(pass);
            const auto start = Clock::now();
            const auto it = baked.find(pass.data.content_hash);
            TextureData data = it != baked.end() ? it->second : produce_upload(pass);
            timings.ao_seconds += seconds_since(start);
            return data;
        });
        for (std::size_t k; (k = next_++) < pending_.size();) {
            {
                std::lock_guard lock(mutex_);
                if (!failure_.empty()) break;
            }
            const std::size_t i = pending_[k];
            const Stimulus& s = set_.stimuli[i];
            const Technique& technique = find_technique(s.technique);

            // The single-image path of `lucent render --mesh`.
            const auto start = Clock::now();
            const double ao_before = timings.ao_seconds;
            const Scene scene = make_scene(meshes_.at(s.mesh), technique, s.values,
                                           set_.width, set_.height);
            RenderedStimulus item{i, render_image_counted(executor, scene)};
            timings.gl_seconds += seconds_since(start) - (timings.ao_seconds - ao_before);

            if (!options_.overlap_encode) {  // encode here, before the next render
                if (!finish_stimulus(item, timings)) break;
                continue;
            }
            std::unique_lock lock(mutex_);
            queue_changed_.wait(lock, [&] {
                return queue_.size() < std::size_t(jobs_) || !failure_.empty();
            });
            if (!failure_.empty()) break;
            queue_.push_back(std::move(item));
            queue_changed_.notify_all();
        }
    } catch (const std::exception& e) {
        std::lock_guard lock(mutex_);
        fail(e.what());
    }
    std::lock_guard lock(mutex_);
    --rendering_;
    queue_changed_.notify_all();
}

void RenderWorkers::encode_worker(int index) {
    BatchTimings& timings = encode_timings_[std::size_t(index)];
    try {
        for (;;) {
            std::optional<RenderedStimulus> item;
            {
                std::unique_lock lock(mutex_);
                queue_changed_.wait(lock, [&] {
                    return !queue_.empty() || rendering_ == 0 || !failure_.empty();
                });
                if (!failure_.empty() || queue_.empty()) return;
                item = std::move(queue_.front());
                queue_.pop_front();
                queue_changed_.notify_all();
            }
            if (!finish_stimulus(*item, timings)) return;
        }
    } catch (const std::exception& e) {
        std::lock_guard lock(mutex_);
        fail(e.what());
    }
}

// The progress line, redrawn as stimuli finish, until all are done or one failed.
void RenderWorkers::show_progress() {
    BatchProgress progress(pending_.size(), options_.progress);
    std::unique_lock lock(mutex_);
    std::size_t shown = 0;
    while (shown < pending_.size() && failure_.empty()) {
        finished_signal_.wait(lock,
                              [&] { return finished_ > shown || !failure_.empty(); });
        while (shown < finished_) {
            const std::string id = finished_ids_[shown++];
            lock.unlock();
            progress.done(shown, id);
            lock.lock();
        }
    }
}

void RenderWorkers::run() {
    std::vector<std::thread> workers;
    for (int w = 0; w < jobs_ && !pending_.empty(); ++w) {
        workers.emplace_back(&RenderWorkers::render_worker, this, w);
        if (options_.overlap_encode)
            workers.emplace_back(&RenderWorkers::encode_worker, this, w);
    }
    show_progress();
    for (auto& thread : workers) thread.join();
    if (!failure_.empty()) throw std::runtime_error(failure_);
}

// The stimuli whose image had NaN or Inf pixels, with the count, in set order.
std::vector<std::pair<std::string, std::size_t>> non_finite_stimuli(
    const StimulusSet& set, const std::vector<ManifestRow>& rows) {
    std::vector<std::pair<std::string, std::size_t>> non_finite;
    for (std::size_t i = 0; i < set.stimuli.size(); ++i) {
        const auto& row = rows[i];
        const auto it = std::find_if(row.begin(), row.end(), [](const ManifestField& f) {
            return f.column == "non_finite_pixels";
        });
        const auto pixels = it == row.end() ? std::nullopt : parse_count(it->text);
        if (pixels && *pixels > 0) non_finite.push_back({set.stimuli[i].id, *pixels});
    }
    return non_finite;
}

// The stage times summed over the pre-bake and every worker (wall time not included).
BatchTimings summed_timings(double prebake_seconds,
                            const std::vector<BatchTimings>& render_timings,
                            const std::vector<BatchTimings>& encode_timings) {
    BatchTimings sum;
    sum.ao_seconds = prebake_seconds;
    for (const auto* timings : {&render_timings, &encode_timings})
        for (const auto& t : *timings) {
            sum.ao_seconds += t.ao_seconds;
            sum.gl_seconds += t.gl_seconds;
            sum.encode_seconds += t.encode_seconds;
            sum.statistics_seconds += t.statistics_seconds;
        }
    return sum;
}

}  // namespace

BatchResult render_stimulus_set(const StimulusSet& set, const BatchOptions& options) {
    const auto wall_start = Clock::now();
    const auto& dir = options.out_dir;
    BatchResult result;

    const MeshesBySpec meshes = load_meshes(set);
    std::filesystem::create_directories(dir);
    const auto previous = read_manifest_csv(dir);

    RenderPlan plan = plan_renders(set, options, meshes, previous);
    result.reused = plan.reused;
    // Drop the rows of everything about to be re-rendered before any file is replaced.
    write_complete_rows(dir, set, plan.rows);

    const Prebaked baked = prebake(set, meshes, plan.pending, options.progress);
    RenderWorkers workers(set, options, meshes, baked.by_hash, plan);
    workers.run();
    result.rendered = plan.pending.size();

    result.non_finite = non_finite_stimuli(set, plan.rows);
    result.rows = std::move(plan.rows);
    result.timings =
        summed_timings(baked.seconds, workers.render_timings(), workers.encode_timings());
    result.timings.wall_seconds = seconds_since(wall_start);
    return result;
}

int run_render_set_command(const std::string& config_path, const std::string& preset,
                           const std::string& out_dir, int jobs, bool force) {
    return run_render_set_command(
        [&] {
            const auto catalog = default_set_catalog();
            return preset.empty() ? load_stimulus_set(config_path, catalog)
                                  : load_set_preset(preset, catalog);
        },
        out_dir, jobs, force);
}

int run_render_set_command(const std::function<StimulusSet()>& load_set,
                           const std::string& out_dir, int jobs, bool force) {
    StimulusSet set;
    try {
        if (out_dir.empty()) throw StimulusSetError("--out: missing (give --out DIR)");
        if (jobs < 1 || jobs > 64)
            throw StimulusSetError("--jobs: " + std::to_string(jobs) +
                                   " is out of range (accepted: 1..64)");
        set = load_set();
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
