#pragma once
// The per-vertex ambient occlusion that the lit techniques' ambient terms read (thesis
// Sec. 3, Eq. 3.5; core/ambient_occlusion.h), planned once for all of them: an ordinary
// CPU-made resource, a one-float vertex stream `vertex_ao` at attribute 2 (mesh.vert's
// a_ambient_occlusion), written by an `upload` pass whose producer is the disk-cached
// bake. Nothing above the plan knows it is AO: the upload is a bake
// (ProductionCost::bake), which is all batch renders, the explorer and the benches look
// at.
#include <string>

#include "renderer/core/frame_plan.h"
#include "renderer/core/scene.h"

namespace lucent {

inline constexpr const char* kAmbientOcclusionStream = "vertex_ao";
inline constexpr int kAmbientOcclusionAttribute = 2;

// Content hash of the bake of (mesh, rays): "ao-<mesh hash>-r<rays>-a<algorithm
// version>", the disk cache's key.
std::string ambient_occlusion_hash(const Mesh& mesh, int rays);

// Creates `vertex_ao` and adds the `ambient_occlusion` upload (described by `purpose` in
// --explain) filling it with load_or_bake_ambient_occlusion(mesh, rays), or the bake
// itself when ProduceOptions::use_caches is false; its stand-in is every vertex open (1).
// Passes that use the AO read `vertex_ao`; when none does, compile() culls the upload.
void add_ambient_occlusion(PlanBuilder& plan, const Scene& scene, int rays,
                           std::string purpose);

}  // namespace lucent
