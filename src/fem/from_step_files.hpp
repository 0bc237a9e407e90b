#pragma once
// Private to fem/from_step.cpp: the files exchanged with gmsh and ccx (geo scripts, the geometry
// report, gmsh's Abaqus/CalculiX mesh, ccx decks and eigenvalue tables).
#include <Eigen/Dense>
#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "piezobench/fem/from_step.hpp"

namespace piezobench::fem::detail {

// One CAD entity reported by gmsh: its tag and bounding box (mm).
struct GeoEntity {
  int tag = 0;
  Box3 box;
};
struct GeometryReport {
  std::vector<GeoEntity> volumes, surfaces;
  Box3 bounds;  // of all volumes
  double volume_mm3 = 0.0, area_mm2 = 0.0;  // of all volumes and all faces (the `A` line)
};

// The geo commands shared by both gmsh runs: OpenCASCADE, millimetres, the STEP file (a name in
// the work folder; it is copied there so that no user text enters the script), each region cut
// out of the bodies (BooleanIntersection with its box, then BooleanFragments of the bodies with
// the pieces, so that the mesh is conforming).
[[nodiscard]] std::string geometry_script(const std::string& step_name, const std::vector<RegionSpec>& regions,
                                          double tolerance_mm);
// Appended to geometry_script for the first run: writes `V tag x0 y0 z0 x1 y1 z1` and
// `S tag ...` lines into `report_name`, then `A volume area` (mm^3, mm^2: gmsh's Mass).
[[nodiscard]] std::string report_script(const std::string& report_name);
// InputError(source, ...) for malformed lines.
[[nodiscard]] GeometryReport parse_geometry_report(const std::string& text, const std::string& source);

// The volume tags of each region (first region whose box holds the volume's box); the others
// belong to "body". InputError for a region with no volume.
[[nodiscard]] std::map<std::string, std::vector<int>> assign_regions(const GeometryReport& g,
                                                                     const std::vector<RegionSpec>& regions,
                                                                     double tolerance_mm);

// Surface tags selected; empty when none. Plane selectors: flat within `tolerance_mm` along the
// axis, at the position within max(tolerance_mm, 1e-4 x the model's diagonal).
[[nodiscard]] std::vector<int> select_faces(const FaceSelector& selector, const GeometryReport& g, double tolerance_mm);
// For messages: the planar faces of `g` perpendicular to each axis with their positions.
[[nodiscard]] std::string describe_planar_faces(const GeometryReport& g, double tolerance_mm);

// Physical groups and mesh options appended to geometry_script for the meshing run: one
// Physical Volume "E_<REGION>" per region, one Physical Surface "F_<POINT>" per remote point.
[[nodiscard]] std::string mesh_script(const std::map<std::string, std::vector<int>>& region_volumes,
                                      const std::vector<std::pair<std::string, std::vector<int>>>& point_surfaces,
                                      double mesh_size_mm, int element_order);

// gmsh's INP export: nodes (mm), volume elements by geometric volume (ELSET=VolumeN), surface
// elements by geometric surface (ELSET=SurfaceN).
struct GmshMesh {
  std::map<long, Eigen::Vector3d> nodes;                     // mm
  std::string volume_type;                                   // C3D4 or C3D10
  std::map<int, std::vector<std::vector<long>>> volume_elements;  // volume tag -> element nodes (id first)
  std::map<int, std::vector<std::vector<long>>> surface_elements; // surface tag -> triangle nodes (id first)
};
// InputError(file, ...) for malformed content, mixed volume element types.
[[nodiscard]] GmshMesh read_gmsh_inp(const std::filesystem::path& file);

// Area (mm^2) and area centroid (mm) of triangles (corner nodes: the 3 first after the id).
struct FacePatch {
  double area = 0.0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  std::vector<long> nodes;  // all nodes of the triangles, sorted, unique
};
[[nodiscard]] FacePatch face_patch(const GmshMesh& mesh, const std::vector<int>& surfaces);

// The ccx decks. `mesh_inp` is written in metres: nodes used by the volume elements, elements per
// region (ELSET E_<REGION>), face node sets (NSET F_<POINT>), the remote nodes (NSET REMOTE).
struct DeckPoint {
  std::string name;
  long ref = -1, rot = -1;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  std::vector<long> nodes;
};
void write_mesh_inp(const std::filesystem::path& file, const GmshMesh& mesh,
                    const std::map<std::string, std::vector<int>>& region_volumes, const std::vector<DeckPoint>& points);
// Materials, sections and rigid bodies; then the step: `*FREQUENCY,SOLVER=MATRIXSTORAGE` when
// clamp is empty, else the clamp point fixed and *FREQUENCY with `modes` modes.
[[nodiscard]] std::string ccx_deck(const std::string& mesh_inp_name, const std::map<std::string, Material>& materials,
                                   const std::vector<std::string>& regions, const std::vector<DeckPoint>& points,
                                   const DeckPoint* clamp, int modes, const std::string& title);

// Frequencies (Hz, the CYCLES/TIME column) of the eigenvalue table of a ccx .dat file.
[[nodiscard]] std::vector<double> read_ccx_frequencies(const std::filesystem::path& dat_file);

// Names usable in ccx sets and gmsh physical groups: [A-Za-z0-9_], 1..40 characters.
[[nodiscard]] bool is_valid_name(const std::string& name);
[[nodiscard]] std::string upper(std::string s);

}  // namespace piezobench::fem::detail
