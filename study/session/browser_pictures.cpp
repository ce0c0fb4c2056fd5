#include "study/session/browser_pictures.h"

#include "renderer/render.h"
#include "study/session/stimulus_source.h"
#include "study/web_series.h"

namespace lucent::study {

StimulusSet browser_picture_set(const Protocol& protocol, const SetCatalog& catalog) {
    const WebSeries series = web_series(protocol);
    const Protocol shown = with_series_pictures(protocol, series);
    StimulusSet set;
    set.name = protocol.name;
    set.source = "study:" + protocol.source;
    set.width = protocol.stimulus_width;
    set.height = protocol.stimulus_height;
    for (const Stimulus& spec : shown.stimuli) {
        if (!spec.live()) continue;  // the protocol's own image file is shown as it is
        const std::string where = protocol.source + ": stimulus '" + spec.id + "': ";
        const auto knobs = catalog.knobs_of(spec.technique);
        if (!knobs)
            throw StimulusError(where + "technique '" + spec.technique + "' is unknown");
        std::vector<KnobAssignment> assignments;
        for (const auto& [name, value] : spec.parameters)
            assignments.push_back({name, value});
        Stimulus s;
        s.id = spec.id;
        s.technique = spec.technique;
        // The same mesh default as the lab's resolution (stimulus_provenance.cpp).
        s.mesh = spec.mesh.empty() ? RenderRequest{}.mesh : spec.mesh;
        s.mesh_name = s.mesh;
        s.parameters = spec.parameters;
        try {
            s.values = resolve_knob_values(*knobs, assignments);
        } catch (const std::exception& e) {
            throw StimulusError(where + e.what());
        }
        // A series's pictures are one factor series of the set's report.
        const size_t at = spec.id.find('@');
        if (at != std::string::npos) s.series = spec.id.substr(0, spec.id.find('='));
        set.stimuli.push_back(std::move(s));
    }
    return set;
}

}  // namespace lucent::study
