// Benchmark-side comparison only (issue 9, item 6): CGAL's Poisson surface
// reconstruction (Kazhdan, Bolitho & Hoppe 2006, the unscreened one: Debian 12
// packages no screened Poisson) through poisson_surface_reconstruction_delaunay,
// on an oriented point file, to set beside points_to_mesh (OpenVDB). Not part of the build:
//   apt-get install libcgal-dev
//   g++ -O2 -std=c++17 -DCGAL_EIGEN3_ENABLED -I/usr/include/eigen3 bench/poisson/poisson_cgal.cpp -o poisson_cgal -lgmp -lmpfr
//   ./poisson_cgal IN.xyz OUT.off      (IN: "x y z nx ny nz" per line)
#include <chrono>
#include <cstdio>
#include <utility>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/boost/graph/IO/polygon_mesh_io.h>
#include <CGAL/IO/read_points.h>
#include <CGAL/Polyhedron_3.h>
#include <CGAL/compute_average_spacing.h>
#include <CGAL/poisson_surface_reconstruction.h>
#include <CGAL/property_map.h>

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Pwn = std::pair<Kernel::Point_3, Kernel::Vector_3>;
using Polyhedron = CGAL::Polyhedron_3<Kernel>;

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: poisson_cgal IN.xyz OUT.off\n");
    return 2;
  }
  std::vector<Pwn> points;
  const auto pm = CGAL::First_of_pair_property_map<Pwn>();
  const auto nm = CGAL::Second_of_pair_property_map<Pwn>();
  if (!CGAL::IO::read_points(argv[1], std::back_inserter(points), CGAL::parameters::point_map(pm).normal_map(nm))) {
    std::fprintf(stderr, "cannot read %s\n", argv[1]);
    return 1;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const double spacing = CGAL::compute_average_spacing<CGAL::Sequential_tag>(points, 6, CGAL::parameters::point_map(pm));
  Polyhedron mesh;
  const bool ok = CGAL::poisson_surface_reconstruction_delaunay(points.begin(), points.end(), pm, nm, mesh, spacing);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!ok) {
    std::fprintf(stderr, "reconstruction failed\n");
    return 1;
  }
  CGAL::IO::write_polygon_mesh(argv[2], mesh, CGAL::parameters::stream_precision(9));
  std::printf("poisson_cgal: %zu points, spacing %.4g -> %zu vertices, %zu faces in %.2f s\n", points.size(), spacing,
              mesh.size_of_vertices(), mesh.size_of_facets(), s);
  return 0;
}
