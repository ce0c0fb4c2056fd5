#pragma once
// Density volumes: a scalar density rho in [0, 1] over the mesh's axis-aligned bounding
// box, a scene input like the mesh (the HTSM technique marches through it). Built from a
// spec: a built-in generator ("marble:frequency=3,seed=2") or an NRRD file. Generators
// use Lucent's own integer hash, never std::*_distribution (which differs between
// standard libraries), so a volume is the same on every machine; its content hash goes
// into manifests and study databases like the mesh hash. GL-free.
//
// Spec grammar (README.md of renderer/techniques/htsm lists every parameter):
//   constant[:value=V]                          rho = V everywhere
//   cube[:size=S,inside=I,outside=O]            a centred box inclusion (Shopf Fig. 5.8)
//   spheres[:count=N,radius=R,inside=I,outside=O,seed=K]   jade-like inclusions
//   marble[:frequency=F,turbulence=A,octaves=N,seed=K]     0.5 + 0.5 sin(2 pi F x + A
//   turb) layers[:count=N,axis=x|y|z]                 0.5 + 0.5 cos(2 pi N t_axis)
//   PATH.nrrd                                   3-D, uchar (/255) or float in [0, 1],
//                                               raw encoding, little endian
#include <glm/glm.hpp>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "renderer/core/knobs.h"

namespace lucent {

// A bad spec or file; what() is one line starting "density: " and naming the field,
// parameter or voxel. A KnobError, so every caller that reports bad knobs reports it.
class DensityError : public KnobError {
public:
    using KnobError::KnobError;
};

struct DensityVolume {
    glm::ivec3 size{1, 1, 1};   // voxels per axis
    std::vector<float> voxels;  // x fastest, then y, then z; each in [0, 1]
    std::string spec;           // as given
    std::string content_hash;   // of size and voxels (16 hex digits)
    float mean = 0.0f;
    float min = 0.0f, max = 0.0f;
    bool constant() const { return min == max; }

    float voxel(int x, int y, int z) const {
        return voxels[(std::size_t(z) * size.y + y) * size.x + x];
    }
    // Trilinear at texture coordinate t in [0, 1]^3 (voxel centres at (i + 1/2) / R,
    // clamped to the edge voxels outside), as a GL linear, clamp-to-edge sampler3D.
    double sample(glm::dvec3 t) const;
};

// The parsed spec: a generator name with its numeric parameters, or a file.
struct DensitySpec {
    std::string generator;  // "constant", "cube", ... ; empty for a file
    std::map<std::string, double> parameters;  // every parameter, defaults filled in
    std::string file;
};
// Checks the syntax and parameter ranges (no file is read). Throws DensityError.
DensitySpec parse_density_spec(std::string_view spec);
// The names of the built-in generators.
const std::vector<std::string>& density_generator_names();

// Builds the volume of `spec`: generators at `resolution`^3 voxels (files keep their
// own size), then the contrast c: rho = clamp(mean + c (rho - mean), 0, 1), so c = 0 is
// homogeneous at the mean. Throws DensityError.
std::shared_ptr<const DensityVolume> make_density_volume(std::string_view spec,
                                                         int resolution, double contrast);

// A volume from voxels (tests, files): fills mean, min, max and the content hash.
DensityVolume finish_density_volume(glm::ivec3 size, std::vector<float> voxels,
                                    std::string spec);

// Writes `volume` as an NRRD file of the supported subset (float, raw, little endian).
void write_density_nrrd(const DensityVolume& volume, const std::string& path);

// The volume of a technique's knob values, when it has a "density" knob (with
// "density_resolution" and "density_contrast"); nullptr otherwise.
std::shared_ptr<const DensityVolume> density_from_knobs(const KnobValues& values);

}  // namespace lucent
