#pragma once
// The walk both estimators run: a ray that alternates between the outside (vacuum, where
// it meets the boundary or escapes) and the medium inside (collisions by
// sample_collision, Henyey-Greenstein scattering with the weight times the albedo,
// Russian roulette), with the smooth dielectric interface between them. The boundary is
// a template parameter: the slab's two planes (slab.cpp) or the mesh through Embree
// (tracer.cpp); it provides
//   std::optional<BoundaryHit> nearest(glm::dvec3 origin, glm::dvec3 direction,
//                                      bool inside, double t_max) const;
// the nearest boundary point ahead of `origin` closer than t_max (the origin may lie on
// the boundary: the boundary skips that point), with the normal pointing out of the
// medium; and double spawn_offset() const, how far off the surface a walk restarts.
#include <cmath>
#include <limits>

#include "renderer/techniques/path/transport.h"

namespace lucent::path {

// How a walk left the boundary for good.
struct Escape {
    glm::dvec3 direction;
    double weight = 0.0;
    // True when the ray met nothing at all (a camera ray that missed the object).
    bool direct = false;
    // The phase-function density with which the last scattering chose `direction`, when
    // nothing changed it since (eta = 1): what multiple importance sampling against a
    // light sampled at that scattering needs. 0 otherwise.
    double phase_pdf = 0.0;
    // The walk left by exactly one refraction after its last scattering (nothing else in
    // between): next-event estimation through that facet (tracer.cpp) could have made
    // the same path, and its multiple importance sampling weight needs these.
    bool one_refraction_after_scattering = false;
    glm::dvec3 scattering_position{0.0};
    glm::dvec3 scattering_direction{0.0};  // the direction the scattering chose
    double scattering_phase_pdf = 0.0;
    std::uint32_t exit_facet = 0;
};

// Walks from `origin` along unit `direction`, starting inside the medium or outside it,
// with `weight`. Calls on_scatter(position, incoming direction, weight after the albedo)
// at each real collision before the new direction is drawn (next-event estimation hooks
// in there), and on_escape(Escape) once if the walk leaves; a walk absorbed, rouletted
// or stopped at the event cap calls neither (the cap is counted in counters.unfinished).
template <class Boundary, class OnScatter, class OnEscape>
void walk(const Boundary& boundary, const ChannelMedium& medium, double medium_eta,
          glm::dvec3 origin, glm::dvec3 direction, bool inside, double weight,
          Random& random, const WalkShortcuts& shortcuts, const WalkLimits& limits,
          WalkCounters& counters, OnScatter&& on_scatter, OnEscape&& on_escape) {
    const bool pass_straight = medium_eta == 1.0 && shortcuts.skip_fresnel_at_eta_1;
    const bool clear =
        medium.sigma_s == 0.0 && shortcuts.no_collisions_without_scattering;
    // A constant medium draws its flight first and asks the boundary only that far (a
    // short ray is cheaper to trace than the whole way to the far side).
    const bool flight_first =
        !clear && medium.density.constant() && shortcuts.no_lookups_in_constant_density;
    const double sigma_constant = medium.sigma_t() * medium.density.constant_value();
    constexpr double kNowhere = std::numeric_limits<double>::infinity();
    bool direct = true;
    double phase_pdf = 0.0;
    Escape last;               // the scattering fields, kept up to date
    int crossings_since = -1;  // interface crossings since the last scattering (-1: none)
    const auto escape = [&](bool is_direct) {
        last.direction = direction;
        last.weight = weight;
        last.direct = is_direct;
        last.phase_pdf = phase_pdf;
        last.one_refraction_after_scattering = crossings_since == 1;
        on_escape(last);
    };
    // Returns false when the walk ends at the collision (absorbed or rouletted).
    const auto scatter_at = [&](double t) {
        origin += t * direction;
        ++counters.scattering_events;
        weight *= medium.albedo();
        if (!(weight > 0.0)) return false;
        on_scatter(origin, direction, weight);
        if (weight < limits.roulette_floor) {
            if (random.uniform() * limits.roulette_floor >= weight) return false;
            weight = limits.roulette_floor;
        }
        const glm::dvec3 incoming = direction;
        direction = sample_henyey_greenstein(medium.g, incoming, random.uniform(),
                                             random.uniform());
        phase_pdf = henyey_greenstein(medium.g, glm::dot(incoming, direction));
        last.scattering_position = origin;
        last.scattering_direction = direction;
        last.scattering_phase_pdf = phase_pdf;
        crossings_since = 0;
        return true;
    };
    for (std::uint64_t events = 0;; ++events) {
        if (events >= limits.max_events) {
            ++counters.unfinished;
            return;
        }
        double flight = kNowhere;
        if (inside && flight_first && sigma_constant > 0.0)
            flight = -std::log1p(-random.uniform()) / sigma_constant;
        ++counters.boundary_queries;
        const std::optional<BoundaryHit> hit =
            boundary.nearest(origin, direction, inside, flight);
        if (!hit && std::isfinite(flight)) {  // the flight ends inside: a collision
            direct = false;
            if (!scatter_at(flight)) return;
            continue;
        }
        if (!hit) {
            if (inside) ++counters.leaks;
            escape(direct);
            return;
        }
        direct = false;
        if (inside && !flight_first) {
            if (clear) {
                // No scattering: the only event is absorption, so the weight takes the
                // transmittance instead of sampling a collision that would end the walk.
                if (medium.sigma_a > 0.0)
                    weight *= transmittance(medium, origin, direction, hit->distance,
                                            random, shortcuts, counters);
                if (!(weight > 0.0)) return;
            } else if (const std::optional<double> t =
                           sample_collision(medium, origin, direction, hit->distance,
                                            random, shortcuts, counters)) {
                if (!scatter_at(*t)) return;
                continue;
            }
        }
        if (!std::isfinite(hit->distance)) {  // a boundary at infinity, never reached
            escape(false);
            return;
        }
        origin += hit->distance * direction;
        const glm::dvec3 outward = hit->outward;
        last.exit_facet = hit->facet;
        if (pass_straight) {
            inside = !inside;
            if (crossings_since >= 0) ++crossings_since;
        } else {
            ++counters.interface_events;
            const InterfaceEvent event =
                cross_interface(direction, outward, medium_eta, random.uniform());
            if (event.transmitted) inside = !inside;
            if (!(event.transmitted && medium_eta == 1.0)) phase_pdf = 0.0;
            // A reflection is not a refraction: the connection through one facet no
            // longer describes this path.
            if (crossings_since >= 0)
                crossings_since = event.transmitted ? crossings_since + 1 : 2;
            direction = event.direction;
        }
        // Off the surface to the side the walk goes on in, so that rounding never puts
        // it on the other side (where it would find no boundary ahead: a leak).
        origin += (inside ? -outward : outward) * boundary.spawn_offset();
    }
}

}  // namespace lucent::path
