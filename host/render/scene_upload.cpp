#include "render/scene_upload.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "colour/blackbody.h"
#include "core/input_error.h"
#include "render/kernel_features.h"
#include "render/light_selection.h"
#include "shared/light.h"
#include "shared/phase.h"
#include "volume/majorant_grid.h"

namespace narval {
namespace {

constexpr float kDegToRad = 3.14159265358979323846f / 180.0f;

nv_float4 f4(float x, float y, float z, float w = 0.0f) { return nv_float4{x, y, z, w}; }
nv_float4 f4(const Vec3f& v, float w = 0.0f) { return nv_float4{v[0], v[1], v[2], w}; }

// Host-side vectors and matrices are GLM's. Vectors are normalised as v / |v| (not GLM's
// v · inversesqrt), which keeps the bits of the uploads the kernels' golden images were made from.
glm::vec3 normalized(const glm::vec3& a) { return a / glm::length(a); }
glm::vec3 v3(const Vec3f& v) { return {v[0], v[1], v[2]}; }
nv_float4 f4(const glm::vec3& v, float w = 0.0f) { return nv_float4{v.x, v.y, v.z, w}; }

// nv_affine (row-major 3x4, the kernels' layout) to and from GLM's column-major 4x4 in double.
glm::dmat4 toGlm(const nv_affine& a) {
  glm::dmat4 m(1.0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) m[j][i] = (&a.row[i].x)[j];
  return m;
}
nv_affine fromGlm(const glm::dmat4& m) {
  nv_affine a;
  for (int i = 0; i < 3; ++i) a.row[i] = nv_float4{float(m[0][i]), float(m[1][i]), float(m[2][i]), float(m[3][i])};
  return a;
}
// M · (p, w): a point (w = 1) or a direction (w = 0), in float as the kernels would.
glm::vec3 apply(const nv_affine& m, const glm::vec3& p, float w) {
  return glm::vec3(glm::mat4(toGlm(m)) * glm::vec4(p, w));
}

nv_affine fromRows(const float m[3][4]) {
  nv_affine a;
  for (int i = 0; i < 3; ++i) a.row[i] = f4(m[i][0], m[i][1], m[i][2], m[i][3]);
  return a;
}

nv_affine rotationOnly(const Transform& t) {
  Transform r;
  r.rotation = t.rotation;
  return transformMatrix(r);
}

// The radius of a sphere about the origin that holds the medium's box (its centre's distance plus
// half its diagonal), 1 without a medium: the scale of a light from infinitely far.
float sceneRadius(const Scene& scene) {
  for (const Primitive& p : scene.primitives)
    if (p.type == PrimitiveType::Volume) {
      const Transform& t = p.transform;
      return glm::length(v3(t.position)) + 0.5f * glm::length(v3(t.scale));
    }
  return 1.0f;
}

// The light of primitive p (light_kinds.h): its transform applied to the unit quad [-0.5, 0.5]² in
// local XY, emitting along local -Z (DESIGN.md, emitters); the emission direction follows the
// rotation alone (scale changes the extent, not the facing). Each kind takes what it needs.
light_params buildLight(const Primitive& p, const Material& m, float sceneRadius) {
  const nv_affine M = transformMatrix(p.transform);
  const glm::vec3 corner = apply(M, {-0.5f, -0.5f, 0.0f}, 1.0f);
  const glm::vec3 eu = apply(M, {1, 0, 0}, 0.0f), ev = apply(M, {0, 1, 0}, 0.0f);
  const glm::vec3 n = normalized(apply(rotationOnly(p.transform), {0, 0, -1}, 0.0f));
  auto toVec3 = [](const glm::vec3& a) { return vec3_make(a.x, a.y, a.z); };
  light_placement pl;
  pl.position = vec3_make(p.transform.position[0], p.transform.position[1], p.transform.position[2]);
  pl.corner = toVec3(corner);
  pl.edge_u = toVec3(eu);
  pl.edge_v = toVec3(ev);
  pl.normal = toVec3(n);
  pl.area = glm::length(glm::cross(eu, ev));
  pl.vector = vec3_make(p.lightVector[0], p.lightVector[1], p.lightVector[2]);
  pl.parameter = p.lightParameter;
  pl.scene_radius = sceneRadius;
  return light_make(p.lightKind, vec3_make(m.albedo[0], m.albedo[1], m.albedo[2]), pl);
}

// The file's index-to-world map of a loaded grid as an nv_affine.
nv_affine gridIndexToFile(const DenseGrid& g) {
  float f[3][4];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) f[r][c] = g.indexToWorld[size_t(r * 4 + c)];
  return fromRows(f);
}

// medium.emission of volume material `materialIndex` (kernels/shared/emission.h) and, for blackbody
// emission from a grid, ds.emissionTable. The emission grid is placed through the file: medium
// index → the density grid's file space → the emission grid's index space, so a grid with another
// transform or bounding box than the density's lands where the file puts it.
void buildEmission(const Scene& scene, int materialIndex, const DenseGrid* density, const DenseGrid* emissionGrid,
                   DeviceScene& ds) {
  const Material& m = scene.materials.at(size_t(materialIndex));
  const Emission& e = m.emission;
  emission_params& ep = ds.params.medium.emission;
  ep = emission_params{};
  const std::string key = "materials[" + std::to_string(materialIndex) + "].emission";
  const bool wantsGrid = !e.grid.empty();
  if (wantsGrid && !emissionGrid)
    throw inputError(scene.sourcePath, key, "the emission grid \"" + e.grid + "\" was not loaded");
  if (wantsGrid) {
    if (!density) throw inputError(scene.sourcePath, key, "an emission grid needs the volume's grid file");
    ep.index_to_grid = affineMultiply(affineInverse(gridIndexToFile(*emissionGrid)), gridIndexToFile(*density));
    ep.grid_dims = f4(float(emissionGrid->nx), float(emissionGrid->ny), float(emissionGrid->nz));
    ds.emissionGrid = emissionGrid;
  }
  switch (e.kind) {
    case EmissionKind::None: ep.kind = EMISSION_NONE; return;
    case EmissionKind::Color:
      ep.kind = EMISSION_COLOR;
      ep.color = f4(e.color[0] * e.scale, e.color[1] * e.scale, e.color[2] * e.scale);
      return;
    case EmissionKind::Blackbody: break;  // below
  }
  if (!wantsGrid) {
    // A constant temperature is a constant colour: B(T) once, here.
    const std::array<float, 3> rgb = blackbodyLinearSrgb(e.temperature);
    ep.kind = EMISSION_COLOR;
    ep.color = f4(rgb[0] * e.scale, rgb[1] * e.scale, rgb[2] * e.scale);
    return;
  }
  ep.kind = EMISSION_BLACKBODY;
  ep.color = f4(e.scale, e.scale, e.scale);
  ep.temperature_offset = e.temperatureOffset;
  ep.temperature_scale = e.temperatureScale;
  // The hottest the grid can give: T is linear in the value, so at one of its extremes (0, the
  // loaders keep values >= 0, or maxValue). The table reaches a little past it.
  const float hottest = std::max((0.0f - e.temperatureOffset) * e.temperatureScale,
                                 (emissionGrid->maxValue - e.temperatureOffset) * e.temperatureScale);
  ep.table_max = std::max(hottest, 200.0f) * 1.001f;
  ep.table_size = kBlackbodyTableSize;
  ds.emissionTable.resize(size_t(3) * kBlackbodyTableSize);
  for (int i = 0; i < kBlackbodyTableSize; ++i) {
    const std::array<float, 3> rgb = blackbodyLinearSrgb(ep.table_max * float(i) / float(kBlackbodyTableSize - 1));
    for (int c = 0; c < 3; ++c) ds.emissionTable[size_t(3 * i + c)] = rgb[size_t(c)];
  }
}

}  // namespace

camera_params buildCamera(const Scene& scene) {
  const Camera& c = scene.camera;
  camera_params cam{};
  const glm::vec3 pos = v3(c.position);
  const glm::vec3 fwd = normalized(v3(c.lookAt) - pos);
  const glm::vec3 right = normalized(glm::cross(fwd, v3(c.up)));
  const glm::vec3 up = glm::cross(right, fwd);
  cam.position = f4(pos);
  cam.forward = f4(fwd);
  cam.right = f4(right);
  cam.up = f4(up);
  cam.width = scene.renderer.width;
  cam.height = scene.renderer.height;
  cam.aspect = float(cam.width) / float(cam.height);
  cam.tan_half_vfov = std::tan(0.5f * c.vfov * kDegToRad);
  cam.lens_radius = c.aperture;
  cam.focus_distance = c.focus;
  return cam;
}

nv_affine transformMatrix(const Transform& t) {
  const float ax = t.rotation[0] * kDegToRad, ay = t.rotation[1] * kDegToRad, az = t.rotation[2] * kDegToRad;
  const float cx = std::cos(ax), sx = std::sin(ax), cy = std::cos(ay), sy = std::sin(ay);
  const float cz = std::cos(az), sz = std::sin(az);
  // R = Rz · Ry · Rx written out (GLM's rotate would round differently), by columns.
  const glm::mat3 R(glm::vec3(cz * cy, sz * cy, -sy), glm::vec3(cz * sy * sx - sz * cx, sz * sy * sx + cz * cx, cy * sx),
                    glm::vec3(cz * sy * cx + sz * sx, sz * sy * cx - cz * sx, cy * cx));
  glm::mat4 M(R * glm::mat3(glm::scale(glm::mat4(1.0f), v3(t.scale))));
  M[3] = glm::vec4(v3(t.position), 1.0f);
  return fromGlm(glm::dmat4(M));
}

nv_affine affineMultiply(const nv_affine& a, const nv_affine& b) { return fromGlm(toGlm(a) * toGlm(b)); }

nv_affine affineInverse(const nv_affine& a) {
  const glm::dmat4 m = toGlm(a);
  const glm::dmat3 linear(m);
  const double det = glm::determinant(linear);
  if (!(std::fabs(det) > 1e-30) || !std::isfinite(det)) throw std::domain_error("singular transform");
  const glm::dmat3 inverse = glm::inverse(linear);
  glm::dmat4 out(inverse);
  out[3] = glm::dvec4(-(inverse * glm::dvec3(m[3])), 1.0);
  return fromGlm(out);
}

bool mediumWorldBounds(const DeviceScene& ds, float lo[3], float hi[3]) {
  const scene_params& sp = ds.params;
  if (!sp.has_medium) return false;
  const nv_affine toWorld = affineInverse(sp.medium.world_to_index);
  const float dims[3] = {sp.medium.dims.x, sp.medium.dims.y, sp.medium.dims.z};
  for (int a = 0; a < 3; ++a) {
    lo[a] = INFINITY;
    hi[a] = -INFINITY;
  }
  for (int corner = 0; corner < 8; ++corner) {
    const float p[3] = {corner & 1 ? dims[0] : 0.0f, corner & 2 ? dims[1] : 0.0f, corner & 4 ? dims[2] : 0.0f};
    for (int a = 0; a < 3; ++a) {
      const nv_float4& row = toWorld.row[a];
      const float w = row.x * p[0] + row.y * p[1] + row.z * p[2] + row.w;
      lo[a] = std::fmin(lo[a], w);
      hi[a] = std::fmax(hi[a], w);
    }
  }
  return true;
}

namespace {

// The medium of volume primitive i (its material, grid and transform) into ds.params.medium, its
// emission and majorant grid into ds.
void buildMedium(const Scene& scene, size_t i, SceneGrids grids, DeviceScene& ds) {
  const DenseGrid* grid = grids.density;
  const Primitive& p = scene.primitives[i];
  const Material& m = scene.materials.at(size_t(p.materialIndex));
  scene_params& sp = ds.params;
  medium_params& med = sp.medium;
  sp.has_medium = 1;
  const float D = m.density;
  med.sigma_a = f4(m.absorption[0] * D, m.absorption[1] * D, m.absorption[2] * D);
  med.sigma_s = f4(m.scattering[0] * D, m.scattering[1] * D, m.scattering[2] * D);
  med.phase = phase_make(m.phase, m.phaseParameter);
  med.grey = m.absorption[0] == m.absorption[1] && m.absorption[1] == m.absorption[2] &&
             m.scattering[0] == m.scattering[1] && m.scattering[1] == m.scattering[2];
  float maxSigmaT = 0.0f;
  for (int c = 0; c < 3; ++c) maxSigmaT = std::max(maxSigmaT, (m.absorption[c] + m.scattering[c]) * D);
  const float maxDensity = grid ? grid->maxValue : 1.0f;
  // Trilinear values never exceed the largest voxel; the margin absorbs float rounding so that
  // 1 - σt/σ̄ never goes negative.
  med.majorant = maxSigmaT * maxDensity * (1.0f + 1e-5f);
  const float dims[3] = {grid ? float(grid->nx) : 1.0f, grid ? float(grid->ny) : 1.0f,
                         grid ? float(grid->nz) : 1.0f};
  med.dims = f4(dims[0], dims[1], dims[2]);
  const std::string key = "primitives[" + std::to_string(i) + "].transform";
  // index -> world: "unit" maps the grid's box onto the primitive's unit cube; "file" keeps
  // the grid's own index-to-world map and applies the primitive transform on top.
  nv_affine indexToWorld;
  if (grid && m.gridSpace == GridSpace::File) {
    float f[3][4];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) f[r][c] = grid->indexToWorld[size_t(r * 4 + c)];
    indexToWorld = affineMultiply(transformMatrix(p.transform), fromRows(f));
  } else {
    const float u[3][4] = {{1 / dims[0], 0, 0, -0.5f}, {0, 1 / dims[1], 0, -0.5f}, {0, 0, 1 / dims[2], -0.5f}};
    indexToWorld = affineMultiply(transformMatrix(p.transform), fromRows(u));
    if (grid && !grid->fileTransformIsScaleTranslate)
      ds.warnings.push_back(scene.sourcePath + ": " + "materials[" + std::to_string(p.materialIndex) +
                            "].gridSpace: the grid's file transform rotates or shears; \"unit\" grid space "
                            "drops it (set \"gridSpace\": \"file\" to keep it)");
  }
  try {
    med.world_to_index = affineInverse(indexToWorld);
  } catch (const std::domain_error&) {
    throw inputError(scene.sourcePath, key, "the volume's transform is singular (a zero scale?)");
  }
  buildEmission(scene, p.materialIndex, grid, grids.emission, ds);
  ds.grid = grid;
  if (grid) {
    const std::array<int, 3> cells = chooseMajorantResolution(grid->nx, grid->ny, grid->nz);
    const MajorantGrid mg = buildMajorantGrid(*grid, cells[0], cells[1], cells[2]);
    med.majorant_grid = mg.params();
    ds.majorants = mg.maxDensity;
  }
}

}  // namespace

DeviceScene buildDeviceScene(const Scene& scene, SceneGrids grids) {
  DeviceScene ds;
  scene_params& sp = ds.params;
  sp.camera = buildCamera(scene);
  sp.background = f4(scene.background);
  sp.max_bounces = scene.renderer.bounces;
  sp.seed = scene.renderer.seed;
  for (size_t i = 0; i < scene.primitives.size(); ++i) {
    const Primitive& p = scene.primitives[i];
    if (p.type == PrimitiveType::Volume)
      buildMedium(scene, i, grids, ds);
    else
      ds.lights.push_back(buildLight(p, scene.materials.at(size_t(p.materialIndex)), sceneRadius(scene)));
  }
  if (ds.majorants.empty()) {
    // One cell over the whole box: density 1 (homogeneous) or 0 (no medium).
    sp.medium.majorant_grid.cell_size = sp.medium.dims;
    sp.medium.majorant_grid.cells_x = sp.medium.majorant_grid.cells_y = sp.medium.majorant_grid.cells_z = 1;
    ds.majorants.assign(1, sp.has_medium ? 1.0f : 0.0f);
  }
  if (ds.emissionTable.empty()) ds.emissionTable.assign(3, 0.0f);
  sp.num_lights = int(ds.lights.size());
  const PathtraceSettings& pt = scene.renderer.pathtrace;
  assignLightSelection(ds, pt.lightSampling);
  sp.shadow_roulette = pt.shadowRoulette;
  if (ds.lights.empty()) ds.lights.push_back(light_params{});  // a buffer may not be empty
  try {
    ds.buildOptions = sceneBuildOptions(ds);  // render/kernel_features.h
  } catch (const InputError& e) {
    throw inputError(scene.sourcePath, "", e.what());  // an unknown kind: named with the scene's file
  }
  return ds;
}

bool setMajorantResolution(DeviceScene& ds, int target) {
  if (target < 0) throw std::invalid_argument("setMajorantResolution: negative target " + std::to_string(target));
  if (target == 0 || !ds.grid || !ds.params.has_medium) return false;
  const DenseGrid& g = *ds.grid;
  const std::array<int, 3> cells = chooseMajorantResolution(g.nx, g.ny, g.nz, target);
  const majorant_grid_params& now = ds.params.medium.majorant_grid;
  if (cells[0] == now.cells_x && cells[1] == now.cells_y && cells[2] == now.cells_z) return false;
  MajorantGrid mg = buildMajorantGrid(g, cells[0], cells[1], cells[2]);
  ds.params.medium.majorant_grid = mg.params();
  ds.majorants = std::move(mg.maxDensity);
  return true;
}

}  // namespace narval
