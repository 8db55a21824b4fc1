// synthesize_surface: validation, texel budget, frames, then one method.
#include <algorithm>
#include <cstdio>
#include <cmath>
#include <memory>
#include <numeric>
#include <string>

#include "exsynth/errors.hpp"
#include "surface/methods.hpp"

namespace exsynth {

namespace {

void validate_options(const SurfaceSynthesisOptions& o) {
  if (!(o.texels_per_unit >= 0) || !std::isfinite(o.texels_per_unit))
    throw InvalidInput("texels_per_unit must be >= 0 (0 = use face_resolution)");
  if (o.min_face_resolution < 1 || o.max_face_resolution < o.min_face_resolution)
    throw InvalidInput("face resolution limits must satisfy 1 <= min_face_resolution <= max_face_resolution");
  if (o.texels_per_unit == 0 && (o.face_resolution < 1 || o.face_resolution > o.max_face_resolution))
    throw InvalidInput("face_resolution must be in [1, " + std::to_string(o.max_face_resolution) + "], got " +
                       std::to_string(o.face_resolution));
  if (!(o.exemplar_scale > 0) || !std::isfinite(o.exemplar_scale))
    throw InvalidInput("exemplar_scale must be > 0");
  if (o.coherent_radius < 1 || o.coherent_radius > 5) throw InvalidInput("coherent_radius must be in [1, 5]");
  if (o.coherent_passes < 1 || o.coherent_passes > 8) throw InvalidInput("coherent_passes must be in [1, 8]");
  if (o.fine_neighborhood < 3 || o.fine_neighborhood % 2 == 0 || o.fine_neighborhood > 11)
    throw InvalidInput("fine_neighborhood must be odd, in [3, 11]");
  if (o.coarse_neighborhood < 1 || o.coarse_neighborhood % 2 == 0 || o.coarse_neighborhood > 11)
    throw InvalidInput("coarse_neighborhood must be odd, in [1, 11]");
  if (o.levels < 0 || o.levels > 6) throw InvalidInput("levels must be in [0, 6] (0 = automatic)");
  if (o.knn < 1 || o.knn > 64) throw InvalidInput("knn must be in [1, 64]");
  if (!(o.knn_tolerance >= 0)) throw InvalidInput("knn_tolerance must be >= 0");
  if (!(o.coherence >= 0) || !std::isfinite(o.coherence)) throw InvalidInput("coherence must be >= 0");
  if (!(o.pca_variance > 0 && o.pca_variance <= 1)) throw InvalidInput("pca_variance must be in (0, 1]");
  if (o.max_pca_dims < 1) throw InvalidInput("max_pca_dims must be >= 1");
}

double bytes_per_texel(const SurfaceSynthesisOptions& o, int channels) {
  // frames (5 float3) + texels + sources + order/flags; multiscale adds its
  // pyramid of values and the feature row being built per thread.
  double b = 5 * 12 + 4.0 * channels + 8 + 9;
  if (o.method == SurfaceMethod::Coherent)  // the neighbour table
    b += 12.0 * ((2 * o.coherent_radius + 1) * (2 * o.coherent_radius + 1) - 1);
  if (o.method == SurfaceMethod::Multiscale)  // pyramid of values, sources + the landing tables
    b += (4.0 * channels + 4) * 4.0 / 3.0 + 8 +
         4.0 * (o.fine_neighborhood * o.fine_neighborhood + o.coarse_neighborhood * o.coarse_neighborhood);
  return b;
}

}  // namespace

namespace {

std::vector<int> face_resolutions(const std::vector<double>& areas, const SurfaceSynthesisOptions& opt) {
  std::vector<int> res(areas.size(), opt.face_resolution);
  if (opt.texels_per_unit > 0) {
    for (std::size_t f = 0; f < res.size(); ++f) {
      const double side = std::ceil(opt.texels_per_unit * std::sqrt(std::max(areas[f], 0.0)) - 1e-9);
      res[f] = int(std::clamp(side, double(opt.min_face_resolution), double(opt.max_face_resolution)));
    }
    const double largest = areas.empty() ? 0.0 : std::sqrt(*std::max_element(areas.begin(), areas.end()));
    if (opt.texels_per_unit * largest > opt.max_face_resolution + 1e-9) {
      char msg[256];
      std::snprintf(msg, sizeof msg, "texels_per_unit %.3g asks for %.3g texels along the largest face, over "
                    "max_face_resolution %d; give texels_per_unit at most %.4g for this mesh", opt.texels_per_unit,
                    opt.texels_per_unit * largest, opt.max_face_resolution, opt.max_face_resolution / largest);
      throw InvalidInput(msg);
    }
  }
  return res;
}

}  // namespace

std::vector<int> surface_face_resolutions(const SubdivSurface& surface, const SurfaceSynthesisOptions& opt) {
  validate_options(opt);
  return face_resolutions(opt.texels_per_unit > 0 ? surface.ptex_face_areas()
                                                  : std::vector<double>(std::size_t(surface.ptex_face_count()), 0.0),
                          opt);
}

SurfaceTexture synthesize_surface(const SubdivSurface& surface, const Image& exemplar,
                                  const SurfaceSynthesisOptions& opt, ExecContext* ctx) {
  validate_options(opt);
  if (exemplar.empty() || exemplar.channels() < 1) throw InvalidInput("exemplar is empty: give an image");
  if (exemplar.channels() > kMaxSurfaceChannels)
    throw InvalidInput("exemplar has " + std::to_string(exemplar.channels()) + " channels; at most " +
                       std::to_string(kMaxSurfaceChannels));
  for (float x : exemplar.values())
    if (!std::isfinite(x)) throw InvalidInput("exemplar has non-finite values");
  const int need = opt.method == SurfaceMethod::Coherent ? 2 * opt.coherent_radius + 1 : opt.fine_neighborhood;
  if (exemplar.width() < need || exemplar.height() < need)
    throw InvalidInput("exemplar is " + std::to_string(exemplar.width()) + "x" + std::to_string(exemplar.height()) +
                       ", smaller than the " + std::to_string(need) + "x" + std::to_string(need) +
                       " neighbourhood; give a larger image");
  const int narrow = std::min(exemplar.width(), exemplar.height());
  if (opt.exemplar_scale > double(narrow) / need) {
    char msg[256];
    std::snprintf(msg, sizeof msg, "exemplar_scale %.3g steps so far per texel that the %dx%d neighbourhood spans "
                  "more than the %dx%d exemplar; give exemplar_scale at most %.3g", opt.exemplar_scale, need, need,
                  exemplar.width(), exemplar.height(), double(narrow) / need);
    throw InvalidInput(msg);
  }
  const std::size_t nv = std::size_t(surface.control_vertex_count());
  if (!opt.field.empty()) {
    if (opt.field.size() != nv)
      throw InvalidInput("field has " + std::to_string(opt.field.size()) + " vectors but the mesh has " +
                         std::to_string(nv) + " vertices; give one vector per vertex");
    for (const auto& v : opt.field)
      if (!v.allFinite()) throw InvalidInput("field has non-finite vectors");
    if (std::none_of(opt.field.begin(), opt.field.end(), [](const auto& v) { return v.squaredNorm() > 0; }))
      throw InvalidInput("field is zero everywhere, so it gives the texture no direction; give a tangent at some "
                         "vertices, or no field for a smooth one");
  }

  const std::vector<double> areas = surface.ptex_face_areas();
  std::vector<int> res = face_resolutions(areas, opt);
  double texels = 0, area_texels = 0;
  for (int r : res) texels += double(r) * r;
  check_memory_budget(texels * bytes_per_texel(opt, exemplar.channels()), opt.memory_budget,
                      "surface synthesis of " + std::to_string(std::size_t(texels)) + " texels",
                      "lower texels_per_unit / face_resolution or raise the memory budget");

  SurfaceTexture out;
  out.channels = exemplar.channels();
  out.face_resolution = res;
  surface::TexelGrid grid(res);
  out.face_offset = grid.offset;
  // Sample spacing: the mean texel size (surface length per texel), over the
  // exemplar scale, so one exemplar pixel covers about one texel.
  double total_area = 0;
  for (std::size_t f = 0; f < res.size(); ++f) {
    total_area += areas[f];
    area_texels += double(res[f]) * res[f];
  }
  out.sample_spacing = std::sqrt(total_area / std::max(area_texels, 1.0)) / opt.exemplar_scale;
  if (!(out.sample_spacing > 0)) throw InvalidInput("control mesh has zero surface area");

  const std::vector<Eigen::Vector3f> field =
      opt.field.empty() ? smooth_surface_field(surface.control_mesh(), opt.field_axis, 50, ctx) : opt.field;
  if (ctx) ctx->set_stage("surface frames");
  const surface::TexelFrames frames = surface::build_texel_frames(surface, grid, field, ctx);
  std::unique_ptr<surface::VertexCharts> charts;
  if (opt.vertex_charts) {
    StageProgress progress(ctx, "surface charts", 0.0, 1.0, 1);
    charts = std::make_unique<surface::VertexCharts>(surface);
    progress.advance();
    progress.check();
  }
  if (opt.method == SurfaceMethod::Coherent)
    surface::run_coherent(surface, frames, charts.get(), exemplar, opt, out, ctx);
  else
    surface::run_multiscale(surface, frames, charts.get(), exemplar, opt, out, ctx);
  return out;
}

SurfaceResult texture_surface(const PolygonMesh& control, const Image& exemplar, const SurfaceSynthesisOptions& opt,
                              const SurfaceOutputOptions& out, ExecContext* ctx) {
  const SubdivSurface surface(control, ctx);
  SurfaceResult r;
  r.texture = synthesize_surface(surface, exemplar, opt, ctx);
  r.atlas = build_surface_atlas(surface, r.texture, out.gutter, ctx);
  r.mesh = surface_limit_mesh(surface, r.texture, r.atlas, out.segments, out.displacement_channel,
                              out.displacement_scale, out.displacement_midlevel, ctx);
  return r;
}

}  // namespace exsynth
