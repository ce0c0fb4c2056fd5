// Resolving a protocol's stimuli to the values the renderer uses, and checking
// pre-rendered files against their stimulus set's manifest.
#include "study/session/stimulus_provenance.h"

#include <filesystem>
#include <map>
#include <memory>

#include "common/content_hash.h"
#include "lucent/version.h"
#include "renderer/core/mesh.h"
#include "renderer/core/technique.h"
#include "renderer/render.h"
#include "renderer/techniques/registry.h"
#include "stimuli/manifest.h"
#include "study/session/stimulus_source.h"

namespace lucent::study {
namespace {

namespace fs = std::filesystem;
using ManifestRows = std::map<std::string, std::map<std::string, std::string>>;

std::string field(const std::map<std::string, std::string>& row,
                  const std::string& column) {
    const auto it = row.find(column);
    return it == row.end() ? std::string() : it->second;
}

// The manifest's text for a knob in canonical form, so "0.50" and "0.5" compare equal;
// text the knob does not accept is returned as written (and then differs).
std::string canonical(const Knob& knob, const std::string& text) {
    try {
        return format_knob_value(parse_knob_value(knob, text));
    } catch (const KnobError&) {
        return text;
    }
}

// Checks `file` (a --images picture of `resolved`) against DIR/manifest.csv and fills
// in the manifest's software and content hash.
void check_against_manifest(StimulusProvenance& resolved, const std::vector<Knob>& knobs,
                            const fs::path& dir, const ManifestRows& manifest,
                            const std::string& file) {
    const std::string manifest_name = (dir / "manifest.csv").string();
    const auto fail = [&](const std::string& reason) -> void {
        throw StimulusError(file + ": " + reason);
    };
    if (manifest.empty())
        fail("no stimulus-set manifest " + manifest_name +
             " to check it against (--images takes the output of 'lucent render CONFIG "
             "--out DIR')");
    const auto it = manifest.find(resolved.stimulus);
    if (it == manifest.end())
        fail("stimulus '" + resolved.stimulus + "' is not listed in " + manifest_name);
    const auto& row = it->second;
    const auto differs = [&](const std::string& what, const std::string& listed,
                             const std::string& wanted) {
        fail(what + " is " + (listed.empty() ? "(none)" : listed) + " in " +
             manifest_name + " but " + wanted + " in the protocol's stimulus '" +
             resolved.stimulus + "'");
    };
    if (field(row, "technique") != resolved.technique)
        differs("technique", field(row, "technique"), resolved.technique);
    if (field(row, "mesh_hash") != resolved.mesh_hash)
        differs("mesh_hash (mesh " + field(row, "mesh") + ")", field(row, "mesh_hash"),
                resolved.mesh_hash + " (mesh " + resolved.mesh + ")");
    for (const auto& [name, value] : resolved.values) {
        const Knob* knob = find_knob(knobs, name);
        const std::string listed =
            knob ? canonical(*knob, field(row, name)) : field(row, name);
        if (listed != value) differs("parameter '" + name + "'", field(row, name), value);
    }
    // The content hash covers every format's file, as the batch renderer computed it.
    common::ContentHash files;
    bool shown_is_listed = false;
    std::string listed_files = field(row, "files");
    for (size_t start = 0; start <= listed_files.size();) {
        const size_t end = std::min(listed_files.find(';', start), listed_files.size());
        const std::string name = listed_files.substr(start, end - start);
        start = end + 1;
        if (name.empty()) continue;
        const fs::path path = dir / name;
        shown_is_listed |= fs::path(file).filename() == name;
        try {
            files.field(common::hash_file(path));
        } catch (const std::exception&) {
            fail("cannot read " + path.string() + ", listed with it in " + manifest_name);
        }
    }
    if (!shown_is_listed) fail("not among the files " + manifest_name + " lists for it");
    if (files.hex() != field(row, "content_hash"))
        fail("content hash " + files.hex() + " differs from " + manifest_name + "'s " +
             field(row, "content_hash") + ": the image changed after it was rendered");
    resolved.source = "images";
    resolved.file = file;
    resolved.content_hash = files.hex();
    resolved.software_version = field(row, "software_version");
    resolved.build_hash = field(row, "build_hash");
}

}  // namespace

std::vector<ResolvedProtocolStimulus> resolve_protocol_stimuli(
    const Protocol& protocol, const std::string& images_dir, const SetCatalog& catalog) {
    const PrerenderedStimuli images(images_dir);
    const ManifestRows manifest =
        images_dir.empty() ? ManifestRows{} : stimuli::read_manifest_csv(images_dir);
    // By spec: each mesh loaded once and shared by every scene that shows it.
    std::map<std::string, std::shared_ptr<const Mesh>> meshes;
    std::vector<ResolvedProtocolStimulus> out;
    for (const Stimulus& spec : protocol.stimuli) {
        StimulusProvenance p;
        p.stimulus = spec.id;
        p.software_version = version_string();
        p.build_hash = build_hash();
        const std::string where = protocol.source + ": stimulus '" + spec.id + "': ";
        if (!spec.live()) {  // the protocol's own image file: shown as it is
            p.source = "image";
            p.file = spec.image;
            try {
                p.content_hash =
                    common::ContentHash().field(common::hash_file(spec.image)).hex();
            } catch (const std::exception& e) {
                throw StimulusError(where + e.what());
            }
            out.push_back({std::move(p), nullptr});
            continue;
        }
        p.source = "live";
        p.technique = spec.technique;
        p.mesh = spec.mesh.empty() ? RenderRequest{}.mesh : spec.mesh;
        const auto knobs = catalog.knobs_of(spec.technique);
        if (!knobs)
            throw StimulusError(where + "technique '" + spec.technique + "' is unknown");
        const std::string file = images.path_for(spec);
        std::shared_ptr<const Scene> scene;
        try {
            std::vector<KnobAssignment> assignments;
            for (const auto& [name, value] : spec.parameters)
                assignments.push_back({name, value});
            auto [mesh, is_new] = meshes.try_emplace(p.mesh);
            if (is_new) mesh->second = std::make_shared<const Mesh>(load_mesh(p.mesh));
            const Technique& technique = find_technique(spec.technique);
            auto built = std::make_shared<Scene>(make_scene(
                mesh->second, technique, resolve_knob_values(*knobs, assignments),
                protocol.stimulus_width, protocol.stimulus_height));
            // A picture shown from a file is not rendered here: only its values and
            // hashes are checked against the manifest below.
            if (file.empty()) technique.check_scene(*built);
            scene = std::move(built);
        } catch (const std::exception& e) {
            throw StimulusError(where + e.what());
        }
        // The row is the scene's own values, in the catalog's knob order.
        for (const Knob& knob : *knobs) {
            p.values.emplace_back(knob.name,
                                  format_knob_value(scene->values.get(knob.name)));
            // An input's content hash beside its spec, like mesh_hash beside the mesh:
            // a changed file under the same spec is noticed.
            if (knob.input_hash)
                p.values.emplace_back(input_hash_column(knob),
                                      knob.input_hash(scene->values));
        }
        p.mesh_hash = scene->mesh->content_hash;
        if (!file.empty()) {
            check_against_manifest(p, *knobs, images_dir, manifest, file);
            scene = nullptr;
        }
        out.push_back({std::move(p), std::move(scene)});
    }
    return out;
}

std::vector<StimulusProvenance> resolve_stimuli(const Protocol& protocol,
                                                const std::string& images_dir,
                                                const SetCatalog& catalog) {
    std::vector<StimulusProvenance> rows;
    for (ResolvedProtocolStimulus& resolved :
         resolve_protocol_stimuli(protocol, images_dir, catalog))
        rows.push_back(std::move(resolved.provenance));
    return rows;
}

}  // namespace lucent::study
