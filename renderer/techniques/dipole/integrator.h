#pragma once
// The CPU reference's scattering integral B(xo) = integral_A E(xi) Rd(|xi - xo|) dA
// (Chang et al. Eq. 3), independent of the GL path: the mesh's triangles are subdivided
// into cells no wider than `cell_size`, each cell gets E = pi Id Ft(eta, N.L) max(N.L, 0)
// V at its centroid (N its triangle's facet normal, scattering.h facet_normal; V by an
// Embree shadow ray), and the sum runs over a Barnes-Hut
// octree (a node far enough away, size / distance < opening_angle, counts as its flux at
// its flux-weighted centroid plus the second-order (quadrupole) term of its spread; JB02
// uses the monopole with 0.3). Cells near xo are subdivided
// further on the fly until they are small against max(distance, zr), so the r -> 0 peak
// of Rd is integrated, not sampled; cells and nodes alike count with their quadrupole.
#include <glm/glm.hpp>
#include <memory>
#include <vector>

#include "renderer/core/mesh.h"
#include "renderer/cpu/ray_caster.h"
#include "renderer/techniques/dipole/scattering.h"

namespace lucent::dipole {

struct IntegratorQuality {
    double cell_size_over_zr = 0.5;     // irradiance cell edge, in units of min zr
    double opening_angle = 0.2;         // Barnes-Hut acceptance size / distance
    double near_field_ratio = 0.25;     // near cells refined to edge < ratio*max(d, zr)
    std::size_t max_cells = 4'000'000;  // the cell edge grows beyond this many cells
    // The same integral with every step halved: the reference's own error estimate is
    // the difference between a quality and its halved().
    IntegratorQuality halved() const {
        IntegratorQuality q = *this;
        q.cell_size_over_zr *= 0.5;
        q.opening_angle *= 0.5;
        q.near_field_ratio *= 0.5;
        q.max_cells *= 4;
        return q;
    }
};

class ScatteringIntegrator {
public:
    // `light_object`: unit direction towards the light in mesh (object) space;
    // `scale_mm` converts mesh units to mm; `visibility`: shadow rays, or nullptr for
    // none (a convex mesh). The integrator is immutable and thread-safe once built.
    ScatteringIntegrator(const Mesh& mesh, double scale_mm, glm::dvec3 light_object,
                         const Material& material, const IntegratorQuality& quality,
                         const RayCaster* visibility);
    ~ScatteringIntegrator();

    // B(xo) / Id per channel (mm^-2 * mm^2 = dimensionless per unit E_perp / pi): the
    // radiosity for a light with Id = 1, xo in mm (object space * scale).
    glm::dvec3 radiosity(glm::dvec3 xo_mm) const;
    // Phi / Id: sum of E A over the lit cells (mm^2).
    double flux() const { return flux_; }
    std::size_t cell_count() const { return cells_.size(); }
    double cell_size() const { return cell_size_; }  // mm
    double total_area() const { return total_area_; }

private:
    struct Cell {
        glm::dvec3 a, b, c, centroid;
        double area = 0.0, irradiance = 0.0;  // E / Id
    };
    struct Node {
        glm::dvec3 lo, hi, centroid;
        glm::dmat3 spread{0.0};  // flux-weighted second moment about the centroid
        double flux = 0.0, size = 0.0;
        int first = 0, count = 0;  // cells, for a leaf
        int child[8] = {-1, -1, -1, -1, -1, -1, -1, -1};
        bool leaf = true;
    };
    int build(int first, int count, int depth);
    glm::dvec3 refine(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c,
                      double irradiance, const glm::dvec3& xo, int depth) const;

    glm::dvec3 expansion(double flux, const glm::dvec3& centroid,
                         const glm::dmat3& spread, const glm::dvec3& xo) const;

    DipoleRgb dipole_;
    double max_sigma_tr_ = 0.0;
    double min_zr_ = 0.0, flux_ = 0.0, cell_size_ = 0.0, total_area_ = 0.0;
    IntegratorQuality quality_;
    std::vector<Cell> cells_;
    std::vector<Node> nodes_;
};

}  // namespace lucent::dipole
