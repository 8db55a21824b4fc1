// Built-in geometry textures: meshes of simple primitives (a height field,
// tori, tubes, stems and petals), periodic with a period dividing the
// exemplar box [0, 1]^2, built over the box plus its padding and sampled
// evenly (sample_surface). Also user exemplars from meshes and height fields.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include <Eigen/Geometry>

#include "exsynth/errors.hpp"
#include "exsynth/memory_budget.hpp"
#include "exsynth/points.hpp"
#include "exsynth/rng.hpp"
#include "points/sampling.hpp"

namespace exsynth {
namespace {

constexpr double kPi = 3.14159265358979323846;
using V3 = Eigen::Vector3f;

// A grid of (nu + 1) x (nv + 1) vertices from surf(u, v), u, v in [0, 1];
// wrap_u / wrap_v join the last row to the first (tori, tubes).
void add_grid(TriangleMesh& m, int nu, int nv, bool wrap_u, bool wrap_v, const std::function<V3(double, double)>& surf) {
  const int base = int(m.vertices.size());
  const int cu = wrap_u ? nu : nu + 1, cv = wrap_v ? nv : nv + 1;
  for (int j = 0; j < cv; ++j)
    for (int i = 0; i < cu; ++i) m.vertices.push_back(surf(double(i) / nu, double(j) / nv));
  auto id = [&](int i, int j) { return base + (j % cv) * cu + (i % cu); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      m.faces.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      m.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
}

void add_height_field(TriangleMesh& m, double lo, double hi, double step, const std::function<double(double, double)>& h) {
  const int n = std::max(2, int(std::ceil((hi - lo) / step)));
  add_grid(m, n, n, false, false, [&](double u, double v) {
    const double x = lo + u * (hi - lo), y = lo + v * (hi - lo);
    return V3(float(x), float(y), float(h(x, y)));
  });
}

void add_torus(TriangleMesh& m, const Eigen::Vector3d& c, const Eigen::Matrix3d& rot, double R, double r) {
  add_grid(m, 48, 16, true, true, [&](double u, double v) {
    const double a = 2 * kPi * u, b = 2 * kPi * v;
    const Eigen::Vector3d p((R + r * std::cos(b)) * std::cos(a), (R + r * std::cos(b)) * std::sin(a), r * std::sin(b));
    return V3((c + rot * p).cast<float>());
  });
}

// A tube of radius r around path(t), t in [0, 1], with `side` as the
// reference for its frame (must not be parallel to the path).
void add_tube(TriangleMesh& m, int segments, double r, const Eigen::Vector3d& side,
              const std::function<Eigen::Vector3d(double)>& path) {
  add_grid(m, 12, segments, true, false, [&](double u, double v) {
    const Eigen::Vector3d p = path(v), t = (path(std::min(1.0, v + 1e-4)) - path(std::max(0.0, v - 1e-4))).normalized();
    const Eigen::Vector3d s = (side - side.dot(t) * t).normalized(), up = t.cross(s);
    const double a = 2 * kPi * u;
    return V3((p + r * (std::cos(a) * s + std::sin(a) * up)).cast<float>());
  });
}

void add_ellipsoid(TriangleMesh& m, const Eigen::Vector3d& c, const Eigen::Matrix3d& rot, const Eigen::Vector3d& radii) {
  add_grid(m, 16, 10, true, false, [&](double u, double v) {
    const double a = 2 * kPi * u, b = kPi * (v - 0.5);
    const Eigen::Vector3d p(radii[0] * std::cos(b) * std::cos(a), radii[1] * std::cos(b) * std::sin(a),
                            radii[2] * std::sin(b));
    return V3((c + rot * p).cast<float>());
  });
}

// Per lattice cell, random numbers that repeat with the box (period 1).
double cell_random(std::uint64_t seed, int i, int j, int period, int stream) {
  const int pi = ((i % period) + period) % period, pj = ((j % period) + period) % period;
  return IndexRng(seed, std::uint64_t(pj * period + pi), std::uint64_t(stream)).uniform();
}

TriangleMesh bumps_mesh(double lo, double hi, std::uint64_t seed) {
  TriangleMesh m;
  const int period = 4;
  const double a = 1.0 / period;
  add_height_field(m, lo, hi, 0.008, [&](double x, double y) {
    double h = 0;
    const int ci = int(std::floor(x / a)), cj = int(std::floor(y / a));
    for (int j = cj - 1; j <= cj + 1; ++j)
      for (int i = ci - 1; i <= ci + 1; ++i) {
        const double bx = (i + 0.25 + 0.5 * cell_random(seed, i, j, period, 1)) * a;
        const double by = (j + 0.25 + 0.5 * cell_random(seed, i, j, period, 2)) * a;
        const double r = a * (0.3 + 0.2 * cell_random(seed, i, j, period, 3));
        const double d2 = ((x - bx) * (x - bx) + (y - by) * (y - by)) / (r * r);
        if (d2 < 1) h = std::max(h, 0.6 * r * std::sqrt(1 - d2));
      }
    return h;
  });
  return m;
}

TriangleMesh chainmail_mesh(double lo, double hi) {
  // Rings on a lattice of pitch a in x, rows a / 2 apart and shifted by a / 2
  // (European 4-in-1); rows tilted alternately about x so each ring passes
  // through its four diagonal neighbours.
  TriangleMesh m;
  const double a = 0.25, R = 0.105, r = 0.022, tilt = 0.5;
  for (int row = int(std::floor(lo / (a / 2))) - 1; row <= int(std::ceil(hi / (a / 2))) + 1; ++row) {
    const double y = row * a / 2, shift = (row & 1) ? a / 2 : 0.0;
    const Eigen::Matrix3d rot = Eigen::AngleAxisd((row & 1) ? tilt : -tilt, Eigen::Vector3d::UnitX()).toRotationMatrix();
    for (int col = int(std::floor(lo / a)) - 1; col <= int(std::ceil(hi / a)) + 1; ++col) {
      const double x = col * a + shift;
      if (x < lo - R || x > hi + R || y < lo - R || y > hi + R) continue;
      add_torus(m, {x, y, 0.06}, rot, R, r);
    }
  }
  return m;
}

TriangleMesh weave_mesh(double lo, double hi) {
  // Threads along x at y = j a and along y at x = i a, heights A cos(pi s / a
  // + pi k) of opposite sign at the crossings: over, under, over ...
  TriangleMesh m;
  const double a = 0.25, r = 0.055, amp = 0.06;
  const int segs = int(std::ceil((hi - lo) / 0.01));
  for (int k = int(std::floor(lo / a)); k <= int(std::ceil(hi / a)); ++k) {
    add_tube(m, segs, r, Eigen::Vector3d::UnitY(), [&](double t) {
      const double x = lo + t * (hi - lo);
      return Eigen::Vector3d(x, k * a, amp + amp * std::cos(kPi * x / a + kPi * k));
    });
    add_tube(m, segs, r, Eigen::Vector3d::UnitX(), [&](double t) {
      const double y = lo + t * (hi - lo);
      return Eigen::Vector3d(k * a, y, amp - amp * std::cos(kPi * y / a + kPi * k));
    });
  }
  return m;
}

TriangleMesh flowers_mesh(double lo, double hi, std::uint64_t seed) {
  TriangleMesh m;
  add_height_field(m, lo, hi, 0.02, [](double, double) { return 0.0; });
  const int period = 4;
  const double a = 1.0 / period;
  for (int j = int(std::floor(lo / a)) - 1; j <= int(std::ceil(hi / a)); ++j)
    for (int i = int(std::floor(lo / a)) - 1; i <= int(std::ceil(hi / a)); ++i) {
      const double x = (i + 0.3 + 0.4 * cell_random(seed, i, j, period, 1)) * a;
      const double y = (j + 0.3 + 0.4 * cell_random(seed, i, j, period, 2)) * a;
      if (x < lo || x > hi || y < lo || y > hi) continue;
      const double height = 0.1 + 0.06 * cell_random(seed, i, j, period, 3);
      const double spin = 2 * kPi * cell_random(seed, i, j, period, 4);
      add_tube(m, 8, 0.008, Eigen::Vector3d::UnitX(), [&](double t) { return Eigen::Vector3d(x, y, t * height); });
      const Eigen::Vector3d top(x, y, height);
      add_ellipsoid(m, top, Eigen::Matrix3d::Identity(), {0.02, 0.02, 0.014});
      for (int p = 0; p < 5; ++p) {
        const double ang = spin + 2 * kPi * p / 5;
        const Eigen::Matrix3d rot = (Eigen::AngleAxisd(ang, Eigen::Vector3d::UnitZ()) *
                                     Eigen::AngleAxisd(-0.35, Eigen::Vector3d::UnitY())).toRotationMatrix();
        add_ellipsoid(m, top + 0.04 * Eigen::Vector3d(std::cos(ang), std::sin(ang), 0.012), rot, {0.03, 0.016, 0.005});
      }
    }
  return m;
}

TriangleMesh builtin_mesh(const std::string& name, double lo, double hi, std::uint64_t seed) {
  if (name == "bumps") return bumps_mesh(lo, hi, seed);
  if (name == "chainmail") return chainmail_mesh(lo, hi);
  if (name == "weave") return weave_mesh(lo, hi);
  if (name == "flowers") return flowers_mesh(lo, hi, seed);
  throw InvalidInput("unknown built-in geometry texture '" + name + "'; choose bumps, chainmail, weave or flowers");
}

void check_density(double density, const char* what) {
  if (!(density > 0) || !std::isfinite(density))
    throw InvalidInput(std::string(what) + ": the density must be a positive number of points per unit area");
}

}  // namespace

OrientedPoints sample_mesh_points(const TriangleMesh& mesh, double density, std::uint64_t seed, std::size_t memory_budget,
                                  ExecContext* ctx) {
  check_density(density, "sample_mesh_points");
  validate_mesh(mesh, "mesh to sample");
  const double count = points::surface_area(mesh) * density;
  char figures[96];
  std::snprintf(figures, sizeof figures, " (%.3g units² of surface at %.3g points per unit²)",
                points::surface_area(mesh), density);
  check_memory_budget(count * 3 * 200.0, memory_budget, "sampling " + format_count(count) + " points" + figures,
                      "lower the density or the surface's size (for a height field: its heights)");
  if (count < 1) throw InvalidInput("the mesh to sample would get no point at this density; raise the density");
  return points::sample_surface(mesh, std::size_t(std::llround(count)), seed, ctx).points;
}

double point_exemplar_surface_ratio(const std::string& name) {
  const double lo = -0.35, hi = 1.35;  // make_point_exemplar's default padding
  return points::surface_area(builtin_mesh(name, lo, hi, 0)) / ((hi - lo) * (hi - lo));
}

PointExemplar make_point_exemplar(const std::string& name, double density, double padding, std::uint64_t seed,
                                  ExecContext* ctx) {
  check_density(density, "make_point_exemplar");
  if (!(padding >= 0) || padding > 2) throw InvalidInput("make_point_exemplar: padding must be in [0, 2] box units");
  const double lo = -padding, hi = 1.0 + padding;
  const TriangleMesh m = builtin_mesh(name, lo, hi, seed);
  PointExemplar ex;
  ex.points = sample_mesh_points(m, density, seed, kDefaultMemoryBudget, ctx);
  // Keep the padded square only (tori and tubes reach a little beyond it).
  OrientedPoints kept;
  for (std::size_t i = 0; i < ex.points.size(); ++i) {
    const V3& p = ex.points.positions[i];
    if (p.x() >= lo && p.x() <= hi && p.y() >= lo && p.y() <= hi) {
      kept.positions.push_back(p);
      kept.normals.push_back(ex.points.normals[i]);
    }
  }
  ex.points = std::move(kept);
  return ex;
}

PointExemplar height_field_exemplar(const std::vector<float>& heights, int rows, int cols, double pixel_size,
                                    double density, int padding, std::uint64_t seed, ExecContext* ctx) {
  check_density(density, "height_field_exemplar");
  if (rows < 2 || cols < 2 || heights.size() != std::size_t(rows) * std::size_t(cols))
    throw InvalidInput("the height field must be at least 2 x 2 pixels, rows x cols values");
  if (!(pixel_size > 0)) throw InvalidInput("the pixel size must be positive");
  if (padding < 0 || 2 * padding >= std::min(rows, cols) - 1)
    throw InvalidInput("the height field's padding (" + std::to_string(padding) +
                       " pixels per side) leaves no exemplar box; lower it or give a larger image");
  for (float h : heights)
    if (!std::isfinite(h)) throw InvalidInput("the height field has NaN or infinite heights");
  TriangleMesh m;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      m.vertices.emplace_back(float(c * pixel_size), float(r * pixel_size), heights[std::size_t(r) * cols + c]);
  for (int r = 0; r + 1 < rows; ++r)
    for (int c = 0; c + 1 < cols; ++c) {
      const int i = r * cols + c;
      m.faces.emplace_back(i, i + 1, i + cols + 1);
      m.faces.emplace_back(i, i + cols + 1, i + cols);
    }
  PointExemplar ex;
  ex.points = sample_mesh_points(m, density, seed, kDefaultMemoryBudget, ctx);
  ex.box_min = Eigen::Vector2d(padding * pixel_size, padding * pixel_size);
  ex.box_max = Eigen::Vector2d((cols - 1 - padding) * pixel_size, (rows - 1 - padding) * pixel_size);
  return ex;
}

void validate_exemplar(const PointExemplar& ex, const char* what) {
  const std::string w(what);
  if (ex.points.positions.empty()) throw InvalidInput(w + " has no points; give an oriented point set");
  if (ex.points.normals.size() != ex.points.positions.size())
    throw InvalidInput(w + " has " + std::to_string(ex.points.normals.size()) + " normals for " +
                       std::to_string(ex.points.positions.size()) +
                       " points; give one unit normal per point (e.g. a .ply with nx ny nz)");
  for (std::size_t i = 0; i < ex.points.size(); ++i) {
    if (!ex.points.positions[i].allFinite() || !ex.points.normals[i].allFinite())
      throw InvalidInput(w + ": point " + std::to_string(i) + " has a NaN or infinite position or normal");
    const float len = ex.points.normals[i].norm();
    if (std::abs(len - 1.0f) > 1e-2f)
      throw InvalidInput(w + ": normal " + std::to_string(i) + " has length " + std::to_string(len) +
                         "; give unit normals (a point set without normals cannot be used)");
  }
  if (!ex.box_min.allFinite() || !ex.box_max.allFinite() || !(ex.box_max.x() > ex.box_min.x()) ||
      !(ex.box_max.y() > ex.box_min.y()))
    throw InvalidInput(w + ": the exemplar box must have box_max > box_min in x and y");
  std::size_t inside = 0;
  for (const auto& p : ex.points.positions)
    inside += p.x() >= ex.box_min.x() && p.x() <= ex.box_max.x() && p.y() >= ex.box_min.y() && p.y() <= ex.box_max.y();
  if (inside == 0) throw InvalidInput(w + ": no point lies inside the exemplar box; move the box onto the points");
}

PointTextureOptions point_texture_preset(const std::string& name) {
  // The weights are the paper's Table 1 rows (w_p = 1): w_n, w_v, w_l, w_d.
  PointTextureOptions o;
  const auto table1 = [&](double w_n, double w_v, double w_l, double w_d) {
    o.w_n = w_n, o.w_v = w_v, o.w_l = w_l, o.w_d = w_d;
  };
  if (name == "default") return o;
  if (name == "heightfield" || name == "bumps") {
    table1(3, 30, 9, 7);
    return o;
  }
  if (name == "chainmail") {
    table1(1, 10, 8, 6);
    o.patch_size = 0.5;  // two ring pitches: a patch carries whole interlocked rings
    o.w_gradient = 0.5;
    o.max_pair_variation = 0.2;
    return o;
  }
  if (name == "weave") {
    table1(2, 15, 6, 5);
    o.patch_size = 0.5;  // one period of the over-under pattern
    o.w_gradient = 0.5;
    return o;
  }
  if (name == "flowers") {
    table1(2, 2, 6, 6);
    o.patch_size = 0.45;
    o.max_pair_variation = 0.25;
    return o;
  }
  throw InvalidInput("unknown point-texture preset '" + name + "'; choose " + std::string(kPointPresetNames));
}

}  // namespace exsynth
