// The default SetCatalog: the technique registry and the built-in meshes.
#include "renderer/core/mesh.h"
#include "renderer/core/stimulus_set.h"
#include "renderer/techniques/registry.h"

namespace lucent {

SetCatalog default_set_catalog() {
    SetCatalog catalog;
    for (const Technique* technique : all_techniques())
        catalog.technique_names.emplace_back(technique->name());
    catalog.builtin_meshes = builtin_mesh_names();
    catalog.knobs_of = [](std::string_view name) -> std::optional<std::vector<Knob>> {
        for (const Technique* technique : all_techniques())
            if (technique->name() == name) return knobs_for(*technique);
        return std::nullopt;
    };
    return catalog;
}

}  // namespace lucent
