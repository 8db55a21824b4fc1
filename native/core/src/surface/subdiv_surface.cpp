// SubdivSurface: Catmull-Clark limit evaluation per ptex face with OpenSubdiv
// Bfr, ptex adjacency from Far, and walking across faces.
#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#include <opensubdiv/bfr/refinerSurfaceFactory.h>
#include <opensubdiv/bfr/surface.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "exsynth/errors.hpp"
#include "exsynth/surface.hpp"
#include "surface/walk.hpp"

namespace exsynth {

namespace osd = OpenSubdiv;

struct SubdivSurface::Impl {
  std::unique_ptr<osd::Far::TopologyRefiner> refiner;
  std::unique_ptr<osd::Bfr::RefinerSurfaceFactory<>> factory;
  std::vector<osd::Bfr::Surface<double>> surfaces;  // per control face
  VertexData positions;
  std::vector<int> ptex_control, ptex_sub, first_ptex;
  // Per ptex edge: an interior edge of an n-gon (neighbour sub-face, t -> 1 - t)
  // or a stretch [tau0, tau1] of a control edge (face, k).
  struct PtexEdge {
    int face = -1, edge = -1;          // interior neighbour
    int control_face = -1, control_edge = -1;
    double tau0 = 0, tau1 = 1;
  };
  std::vector<std::array<PtexEdge, 4>> edges;
  std::vector<int> twin_face, twin_edge;  // per control half-edge (face_start[f] + k)
  std::vector<std::size_t> face_start;
  int vertex_count = 0;
  PolygonMesh control;

  template <class Fn>
  void evaluate_on(const SurfacePoint& p, Fn&& fn) const {
    const int cf = ptex_control[std::size_t(p.face)];
    const auto& s = surfaces[std::size_t(cf)];
    double uv[2] = {p.u, p.v};
    double scale = 1.0;
    const osd::Bfr::Parameterization param = s.GetParameterization();
    if (param.HasSubFaces()) {
      const double sub[2] = {p.u, p.v};
      param.ConvertNormalizedSubFaceToCoord(ptex_sub[std::size_t(p.face)], sub, uv);
      // Bfr's derivatives are per the tiled domain; a sub-face spans half a tile.
      scale = 0.5;
    }
    fn(s, cf, uv, scale);
  }
};

namespace {

void validate_control_mesh(const PolygonMesh& m) {
  if (m.vertices.empty()) throw InvalidInput("control mesh has no vertices: give a mesh with faces");
  if (m.face_sizes.empty()) throw InvalidInput("control mesh has no faces: give a mesh with at least one polygon");
  Eigen::Vector3f lo = m.vertices[0], hi = m.vertices[0];
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    if (!m.vertices[i].allFinite())
      throw InvalidInput("control mesh vertex " + std::to_string(i) + " is not finite");
    lo = lo.cwiseMin(m.vertices[i]);
    hi = hi.cwiseMax(m.vertices[i]);
  }
  std::size_t total = 0;
  for (std::size_t f = 0; f < m.face_sizes.size(); ++f) {
    if (m.face_sizes[f] < 3)
      throw InvalidInput("control mesh face " + std::to_string(f) + " has " + std::to_string(m.face_sizes[f]) +
                         " vertices; every face needs at least 3");
    total += std::size_t(m.face_sizes[f]);
  }
  if (total != m.face_vertices.size())
    throw InvalidInput("control mesh face_vertices has " + std::to_string(m.face_vertices.size()) +
                       " entries but face_sizes add up to " + std::to_string(total));
  const double diag2 = double((hi - lo).squaredNorm());
  std::unordered_map<std::uint64_t, int> directed;  // directed edge -> face
  std::unordered_map<std::uint64_t, int> undirected;
  directed.reserve(total * 2);
  undirected.reserve(total * 2);
  const int nv = int(m.vertices.size());
  std::size_t at = 0;
  for (std::size_t f = 0; f < m.face_sizes.size(); ++f) {
    const int n = m.face_sizes[f];
    Eigen::Vector3d area(0, 0, 0);
    for (int i = 0; i < n; ++i) {
      const int a = m.face_vertices[at + i], b = m.face_vertices[at + (i + 1) % n];
      if (a < 0 || a >= nv)
        throw InvalidInput("control mesh face " + std::to_string(f) + " names vertex " + std::to_string(a) +
                           ", out of range [0, " + std::to_string(nv) + ")");
      for (int j = i + 1; j < n; ++j)
        if (m.face_vertices[at + j] == a)
          throw InvalidInput("control mesh face " + std::to_string(f) + " uses vertex " + std::to_string(a) +
                             " twice; merge or remove the degenerate face");
      if (b < 0 || b >= nv) continue;  // reported when it is 'a'
      area += m.vertices[a].cast<double>().cross(m.vertices[b].cast<double>());
      const std::uint64_t key = (std::uint64_t(std::uint32_t(a)) << 32) | std::uint32_t(b);
      if (!directed.emplace(key, int(f)).second)
        throw InvalidInput("control mesh is non-manifold or inconsistently oriented at edge (" + std::to_string(a) +
                           ", " + std::to_string(b) + ") of face " + std::to_string(f) +
                           "; recalculate normals / split non-manifold edges (Mesh > Clean Up)");
      const std::uint64_t ukey = (std::uint64_t(std::uint32_t(std::min(a, b))) << 32) | std::uint32_t(std::max(a, b));
      if (++undirected[ukey] > 2)
        throw InvalidInput("control mesh is non-manifold: edge (" + std::to_string(a) + ", " + std::to_string(b) +
                           ") has more than two faces; split non-manifold edges (Mesh > Clean Up)");
    }
    if (!(0.5 * area.norm() > 1e-12 * std::max(diag2, 1e-30)))
      throw InvalidInput("control mesh face " + std::to_string(f) +
                         " has zero area; dissolve degenerate faces (Mesh > Clean Up > Degenerate Dissolve)");
    at += std::size_t(n);
  }
}

}  // namespace

SubdivSurface::SubdivSurface(const PolygonMesh& control, ExecContext* ctx) : impl_(std::make_unique<Impl>()) {
  StageProgress progress(ctx, "subdivision surface", 0.0, 1.0, control.face_sizes.size());
  validate_control_mesh(control);
  Impl& im = *impl_;
  im.vertex_count = int(control.vertices.size());
  im.control = control;

  using Descriptor = osd::Far::TopologyDescriptor;
  Descriptor desc;
  desc.numVertices = im.vertex_count;
  desc.numFaces = int(control.face_sizes.size());
  desc.numVertsPerFace = control.face_sizes.data();
  desc.vertIndicesPerFace = control.face_vertices.data();
  osd::Sdc::Options sdc;
  sdc.SetVtxBoundaryInterpolation(osd::Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
  sdc.SetFVarLinearInterpolation(osd::Sdc::Options::FVAR_LINEAR_ALL);
  using Factory = osd::Far::TopologyRefinerFactory<Descriptor>;
  im.refiner.reset(Factory::Create(desc, Factory::Options(osd::Sdc::SCHEME_CATMARK, sdc)));
  if (!im.refiner) throw InvalidInput("control mesh topology was rejected by OpenSubdiv (non-manifold?)");

  osd::Bfr::SurfaceFactory::Options fopt;
  // Level 3 matches Blender's Subdivision modifier (limit surface) to ~3e-7;
  // the default 2 is off by ~1e-2 near extraordinary vertices.
  fopt.SetApproxLevelSmooth(3);
  im.factory = std::make_unique<osd::Bfr::RefinerSurfaceFactory<>>(*im.refiner, fopt);

  const int nf = desc.numFaces;
  im.surfaces.resize(std::size_t(nf));
  std::vector<double> points(std::size_t(im.vertex_count) * 3);
  for (int i = 0; i < im.vertex_count; ++i)
    for (int k = 0; k < 3; ++k) points[std::size_t(i) * 3 + k] = control.vertices[std::size_t(i)][k];
  im.positions.dim = 3;
  im.positions.patch_points.resize(std::size_t(nf));
  const osd::Bfr::Surface<double>::PointDescriptor pd(3);
  for (int f = 0; f < nf; ++f) {
    auto& s = im.surfaces[std::size_t(f)];
    if (!im.factory->InitVertexSurface(f, &s))
      throw InvalidInput("control mesh face " + std::to_string(f) + " has no limit surface (a hole?)");
    auto& pp = im.positions.patch_points[std::size_t(f)];
    pp.resize(std::size_t(s.GetNumPatchPoints()) * 3);
    s.PreparePatchPoints(points.data(), pd, pp.data(), pd);
    if ((f & 1023) == 0) progress.check();
    progress.advance();
  }

  osd::Far::PtexIndices ptex(*im.refiner);
  const int np = ptex.GetNumFaces();
  im.ptex_control.resize(std::size_t(np));
  im.ptex_sub.resize(std::size_t(np));
  im.first_ptex.resize(std::size_t(nf));
  im.edges.resize(std::size_t(np));
  // Twins of control half-edges, from the (validated, manifold) mesh.
  im.face_start.resize(std::size_t(nf) + 1, 0);
  for (int f = 0; f < nf; ++f) im.face_start[std::size_t(f) + 1] = im.face_start[std::size_t(f)] + std::size_t(control.face_sizes[std::size_t(f)]);
  std::unordered_map<std::uint64_t, std::size_t> half_edges;
  auto key = [](int a, int b) { return (std::uint64_t(std::uint32_t(a)) << 32) | std::uint32_t(b); };
  for (int f = 0; f < nf; ++f) {
    const int n = control.face_sizes[std::size_t(f)];
    for (int k = 0; k < n; ++k)
      half_edges[key(control.face_vertices[im.face_start[std::size_t(f)] + std::size_t(k)],
                     control.face_vertices[im.face_start[std::size_t(f)] + std::size_t((k + 1) % n)])] =
          im.face_start[std::size_t(f)] + std::size_t(k);
  }
  im.twin_face.assign(im.face_start.back(), -1);
  im.twin_edge.assign(im.face_start.back(), -1);
  for (int f = 0; f < nf; ++f) {
    const int n = control.face_sizes[std::size_t(f)];
    for (int k = 0; k < n; ++k) {
      const std::size_t h = im.face_start[std::size_t(f)] + std::size_t(k);
      const auto it = half_edges.find(key(control.face_vertices[im.face_start[std::size_t(f)] + std::size_t((k + 1) % n)],
                                          control.face_vertices[h]));
      if (it == half_edges.end()) continue;
      const std::size_t g = std::size_t(std::upper_bound(im.face_start.begin(), im.face_start.end(), it->second) -
                                        im.face_start.begin()) - 1;
      im.twin_face[h] = int(g);
      im.twin_edge[h] = int(it->second - im.face_start[g]);
    }
  }
  for (int f = 0; f < nf; ++f) {
    const int first = ptex.GetFaceId(f);
    im.first_ptex[std::size_t(f)] = first;
    const int n = control.face_sizes[std::size_t(f)];
    if (n == 4) {
      im.ptex_control[std::size_t(first)] = f;
      im.ptex_sub[std::size_t(first)] = 0;
      for (int e = 0; e < 4; ++e) im.edges[std::size_t(first)][std::size_t(e)] = {-1, -1, f, e, 0.0, 1.0};
      continue;
    }
    for (int q = 0; q < n; ++q) {
      const std::size_t p = std::size_t(first + q);
      im.ptex_control[p] = f;
      im.ptex_sub[p] = q;
      int faces[4], edges[4];
      ptex.GetAdjacency(*im.refiner, f, q, faces, edges);
      // Sub-face q: edge 0 = first half of control edge q, edge 3 = second
      // half of control edge q - 1; edges 1 and 2 are inside the n-gon.
      im.edges[p][0] = {-1, -1, f, q, 0.0, 0.5};
      im.edges[p][3] = {-1, -1, f, (q + n - 1) % n, 0.5, 1.0};
      for (int e : {1, 2}) im.edges[p][std::size_t(e)] = {faces[e], edges[e], -1, -1, 0.0, 1.0};
    }
  }
}

SubdivSurface::EdgeCrossing SubdivSurface::cross_edge(int ptex, int edge, double t) const {
  const Impl& im = *impl_;
  const Impl::PtexEdge& pe = im.edges[std::size_t(ptex)][std::size_t(edge)];
  EdgeCrossing out;
  if (pe.control_face < 0) {
    out = {pe.face, pe.edge, 1 - t, 1.0};
    return out;
  }
  const std::size_t h = im.face_start[std::size_t(pe.control_face)] + std::size_t(pe.control_edge);
  const int g = im.twin_face[h];
  if (g < 0) return out;  // boundary
  const int k = im.twin_edge[h];
  const double tau = 1 - (pe.tau0 + t * (pe.tau1 - pe.tau0));  // on g's edge k, counter-clockwise for g
  const double span = pe.tau1 - pe.tau0;
  const int n = im.control.face_sizes[std::size_t(g)];
  const int first = im.first_ptex[std::size_t(g)];
  if (n == 4) {
    out = {first, k, tau, span};
  } else if (tau < 0.5) {
    out = {first + k, 0, 2 * tau, 2 * span};
  } else {
    out = {first + (k + 1) % n, 3, 2 * tau - 1, 2 * span};
  }
  return out;
}

SubdivSurface::~SubdivSurface() = default;
SubdivSurface::SubdivSurface(SubdivSurface&&) noexcept = default;
SubdivSurface& SubdivSurface::operator=(SubdivSurface&&) noexcept = default;

int SubdivSurface::ptex_face_count() const { return int(impl_->ptex_control.size()); }
int SubdivSurface::control_vertex_count() const { return impl_->vertex_count; }
const PolygonMesh& SubdivSurface::control_mesh() const { return impl_->control; }
int SubdivSurface::control_face(int ptex) const { return impl_->ptex_control.at(std::size_t(ptex)); }
int SubdivSurface::sub_face(int ptex) const { return impl_->ptex_sub.at(std::size_t(ptex)); }
int SubdivSurface::first_ptex_face(int cf) const { return impl_->first_ptex.at(std::size_t(cf)); }

LimitFrame SubdivSurface::evaluate(const SurfacePoint& p) const {
  LimitFrame out;
  impl_->evaluate_on(p, [&](const osd::Bfr::Surface<double>& s, int cf, const double* uv, double scale) {
    double P[3], Du[3], Dv[3];
    s.Evaluate(uv, impl_->positions.patch_points[std::size_t(cf)].data(),
               osd::Bfr::Surface<double>::PointDescriptor(3), P, Du, Dv);
    out.position = Eigen::Vector3d(P[0], P[1], P[2]);
    out.du = scale * Eigen::Vector3d(Du[0], Du[1], Du[2]);
    out.dv = scale * Eigen::Vector3d(Dv[0], Dv[1], Dv[2]);
  });
  return out;
}

SubdivSurface::VertexData SubdivSurface::prepare_vertex_data(const std::vector<float>& data, int dim) const {
  if (dim < 1 || data.size() != std::size_t(impl_->vertex_count) * std::size_t(dim))
    throw InvalidInput("vertex data must have " + std::to_string(dim) + " values per control vertex (" +
                       std::to_string(impl_->vertex_count) + " vertices), got " + std::to_string(data.size()));
  std::vector<double> pts(data.begin(), data.end());
  VertexData out;
  out.dim = dim;
  out.patch_points.resize(impl_->surfaces.size());
  const osd::Bfr::Surface<double>::PointDescriptor pd(dim);
  for (std::size_t f = 0; f < impl_->surfaces.size(); ++f) {
    const auto& s = impl_->surfaces[f];
    out.patch_points[f].resize(std::size_t(s.GetNumPatchPoints()) * std::size_t(dim));
    s.PreparePatchPoints(pts.data(), pd, out.patch_points[f].data(), pd);
  }
  return out;
}

void SubdivSurface::evaluate_data(const VertexData& data, const SurfacePoint& p, double* out) const {
  impl_->evaluate_on(p, [&](const osd::Bfr::Surface<double>& s, int cf, const double* uv, double) {
    s.Evaluate(uv, data.patch_points[std::size_t(cf)].data(), osd::Bfr::Surface<double>::PointDescriptor(data.dim),
               out);
  });
}

SubdivSurface::Neighbour SubdivSurface::neighbour(int ptex, int edge) const {
  const EdgeCrossing c = cross_edge(ptex, edge, 0.5);
  return {c.face, c.edge};
}

bool SubdivSurface::walk(SurfacePoint& p, Eigen::Vector3d d) const {
  return surface::walk_surface([this](const SurfacePoint& q) { return evaluate(q); },
                               [this](int f, int e, double t) { return cross_edge(f, e, t); }, p, d);
}

std::vector<double> SubdivSurface::ptex_face_areas() const {
  // 3-point Gauss-Legendre per direction.
  static const double x[3] = {0.5 - 0.5 * std::sqrt(0.6), 0.5, 0.5 + 0.5 * std::sqrt(0.6)};
  static const double w[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};
  std::vector<double> areas(std::size_t(ptex_face_count()), 0.0);
  // Faces in parallel, each summed in a fixed order: the same areas whatever the thread count.
  tbb::parallel_for(tbb::blocked_range<int>(0, ptex_face_count(), 256), [&](const tbb::blocked_range<int>& r) {
    for (int f = r.begin(); f < r.end(); ++f)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          const LimitFrame fr = evaluate({f, x[i], x[j]});
          areas[std::size_t(f)] += w[i] * w[j] * fr.du.cross(fr.dv).norm();
        }
  });
  return areas;
}

}  // namespace exsynth
