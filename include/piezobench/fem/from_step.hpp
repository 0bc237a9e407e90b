#pragma once
// From CAD to super element with open tools (issue 8): Gmsh meshes a STEP file, CalculiX (ccx)
// assembles the stiffness and mass matrices, piezobench reduces them (Craig-Bampton, see
// craig_bampton.hpp) and writes the super element in its own formats.
//
//  1. gmsh (external program) loads the STEP file with OpenCASCADE in millimetres and reports its
//     volumes and faces (bounding boxes). Each region (a box, mm) is cut out of the bodies with
//     boolean operations, so that it becomes its own volume with a conforming mesh; every volume
//     outside the regions belongs to the region "body".
//  2. Remote points select CAD faces (FaceSelector); each becomes a 6-DOF node of the super element
//     through a CalculiX *RIGID BODY (REF NODE at the area centroid of the faces, ROT NODE beside
//     it). A selector that selects no face is an InputError.
//  3. gmsh meshes with tetrahedra (C3D10 by default, or C3D4) of at most `mesh_size_mm`.
//  4. ccx runs *FREQUENCY,SOLVER=MATRIXSTORAGE on the free-free model (the .sti/.mas/.dof dumps;
//     ccx 2.20's *SUBSTRUCTURE GENERATE is not used, see DESIGN.md).
//  5. craig_bampton() keeps the remote points as interface and `modes` fixed-interface modes;
//     write_super_element() and write_simscape() write the result into the output folder.
//  6. With `verify`, ccx also runs *FREQUENCY on the full mesh with the `clamp` remote point fixed,
//     for comparison with the reduced model's modes under the same boundary condition.
//
// The programs run without a shell (posix_spawn), in a work folder inside the output folder
// (removed at the end unless keep_temp); their logs and the ccx decks stay in the output folder.
// Units: the STEP geometry, mesh sizes, boxes and plane positions in mm; everything written in SI.
#include <Eigen/Dense>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "piezobench/fem/beam.hpp"
#include "piezobench/fem/craig_bampton.hpp"
#include "piezobench/fem/superelement.hpp"

namespace piezobench::fem {

// An axis-aligned box, mm.
struct Box3 {
  Eigen::Vector3d lo = Eigen::Vector3d::Zero();
  Eigen::Vector3d hi = Eigen::Vector3d::Zero();
  // "x0,y0,z0,x1,y1,z1" (corners in any order); InputError naming `field` otherwise.
  static Box3 parse(const std::string& text, const std::string& field);
  // tolerance: mm.
  [[nodiscard]] bool contains(const Box3& other, double tolerance) const;
};

// Which CAD faces a remote point stands for.
//  - "y=max", "x=min", "z=12.5": the planar faces perpendicular to that axis lying in the plane at
//    the model's largest / smallest coordinate, or at the given coordinate (mm; within 1e-4 of the
//    model's size);
//  - "box:x0,y0,z0,x1,y1,z1": the faces whose bounding box lies inside the box (mm);
//  - "surface:12,15": gmsh surface tags (as listed in geometry.txt of the output folder).
struct FaceSelector {
  enum class Kind { kPlane, kBox, kSurfaces };
  enum class At { kMin, kMax, kValue };
  Kind kind = Kind::kPlane;
  int axis = 0;           // plane: 0 x, 1 y, 2 z
  At at = At::kMax;       // plane
  double value = 0.0;     // plane at a coordinate, mm
  Box3 box;               // box
  std::vector<int> surfaces;
  // InputError naming `field` for anything else.
  static FaceSelector parse(const std::string& text, const std::string& field);
  [[nodiscard]] std::string to_string() const;
};

struct RemotePointSpec {
  std::string name;       // letters, digits, '_' (at most 40 characters)
  FaceSelector selector;
  // "NAME:SELECTOR", e.g. "top:y=max".
  static RemotePointSpec parse(const std::string& text, const std::string& field);
};

// A region cut out of the bodies by a box (mm); its material is given by name.
struct RegionSpec {
  std::string name;       // letters, digits, '_'; "body" is reserved for the rest
  Box3 box;
  // "NAME:box:x0,y0,z0,x1,y1,z1".
  static RegionSpec parse(const std::string& text, const std::string& field);
};

// Linear isotropic elastic material, or `removed`: the region is cut out of the model (not meshed),
// e.g. a block standing for a stack in the CAD, replaced by stack beams (StackSpec).
struct Material {
  double youngs_modulus = 0.0;  // Pa
  double poisson_ratio = 0.0;   // -
  double density = 0.0;         // kg/m^3
  bool removed = false;
  // "E,nu,rho" (SI) or "none" (removed); InputError naming `field` unless E > 0, -1 < nu < 0.5, rho > 0.
  static Material parse(const std::string& text, const std::string& field);
};

// A node of the super element that is not on the CAD (a junction between two stacks): on the line
// from remote point (or joint) `from` to `to`, at from + fraction (to - from), 0 < fraction < 1.
struct JointSpec {
  std::string name, from, to;
  double fraction = 0.5;
  // "NAME:FROM:TO:FRACTION".
  static JointSpec parse(const std::string& text, const std::string& field);
};

// A stack (or stacks in series) between two remote points or joints: a beam added to the reduced
// model (beam.hpp), touching the shell only through the faces of its end remote points.
struct StackSpec {
  std::string from, to;
  BeamSection section;  // default: Table 4.1 (c^E 48 GPa, 1 cm^2), nu 0.31, 7800 kg/m^3
  // "FROM:TO" or "FROM:TO:E,nu,rho,AREA".
  static StackSpec parse(const std::string& text, const std::string& field);
};

// What a mesh size costs, estimated from the geometry before gmsh meshes (fitted on APA95ML.step
// and apa300ml.geo meshes, docs/from-step.md): elements ~ 3 V / h^3 + 4 S / h^2 (V volume, S
// surface area, h mesh size), nodes and DOF per element from the element order, peak memory and
// time of the chain from the measured 2 mm APA95ML run (144k DOF: 1.5 GB, 40-95 s) scaled by DOF^1.2.
struct MeshEstimate {
  double volume_mm3 = 0.0, area_mm2 = 0.0;         // mm^3, mm^2
  double elements = 0.0, nodes = 0.0, dofs = 0.0;  // counts
  double memory_GB = 0.0;                          // GB
  double seconds = 0.0;
  [[nodiscard]] std::string to_string() const;
};
// volume_mm3: mm^3; area_mm2: mm^2.
[[nodiscard]] MeshEstimate estimate_mesh(double volume_mm3, double area_mm2, double mesh_size_mm, int element_order);
// The default of FromStepOptions::max_memory_GB: half the physical memory, at most 8 GB.
[[nodiscard]] double default_max_memory_GB();

// Defaults for APA95ML.step (../shared/data/apa95ml-ansys, one body: the shell fused with a block
// standing for the stack): see FromStepOptions::apa95ml().
struct FromStepOptions {
  double mesh_size_mm = 4.0;         // gmsh Mesh.MeshSizeMax
  int element_order = 2;             // 2: C3D10 (default), 1: C3D4
  int modes = 30;                    // fixed-interface modes kept
  double geometry_tolerance_mm = 1e-3;  // gmsh Geometry.ToleranceBoolean; flatness of planar faces
  std::vector<RegionSpec> regions;
  std::map<std::string, Material> materials;  // by region name; "body" for the rest
  std::vector<RemotePointSpec> remote_points;
  std::vector<JointSpec> joints;     // extra 6-DOF nodes (stack junctions), after the remote points
  std::vector<StackSpec> stacks;     // beams between remote points / joints, added after the reduction
  // A .geo input (gmsh script, e.g. apa300ml.geo) is exported to STEP first, with these
  // DefineConstant values (gmsh -setnumber NAME VALUE).
  std::map<std::string, double> geo_parameters;
  // Refuse (UsageError, exit code 2) when the estimated peak memory of the chain exceeds this
  // (GB); 0: default_max_memory_GB(). The tools also run under a memory limit of twice this
  // (address space) plus 1 GB, and each for at most tool_timeout_s.
  double max_memory_GB = 0.0;
  double tool_timeout_s = 3600.0;
  std::string clamp;                 // remote point fixed for modes_clamped_Hz (and --verify)
  // The static stiffness reported (with `clamp` fixed): remote point and direction, "NAME:DIR",
  // e.g. "top:y" (the presets); empty: none.
  std::string axial;
  int clamped_modes = 10;            // number of clamped modes reported (and asked from ccx)
  bool verify = false;               // also ccx *FREQUENCY on the full mesh, `clamp` fixed
  bool keep_temp = false;            // keep the work folder (mesh, matrix dumps, ccx results)
  std::filesystem::path out = "superelement-from-step";
  std::string stem;                  // file names in `out`; default: the STEP file's stem
  std::string gmsh = "gmsh";         // executable: a name looked up in PATH, or a path
  std::string ccx = "ccx";
  // Progress and log lines (may be empty).
  std::function<void(const std::string&)> log;

  // APA95ML.step: region "stack" = the block |x| <= 34.7793, |y| <= 10, |z| <= 11.25 mm, PZT
  // (E 48 GPa = c^E of the report's Table 4.1, nu 0.31, 7800 kg/m^3); "body" (the shell) steel
  // (E 190 GPa as in the report's model, nu 0.3, 7800 kg/m^3); remote points top (y=max),
  // bottom (y=min), stack_a (x=-34.7793) and stack_b (x=34.7793); clamp "bottom".
  static FromStepOptions apa95ml();
  // APA95ML.step modelled as the Ansys super element has it (docs/from-step.md): the block removed
  // (material none), the stack a beam of four segments (joints j1..j3) between stack_a and stack_b,
  // which hold the end faces and the shell's arch feet (|x| >= 28.7 mm on y = +-10), with the
  // axial stiffness (3.72e7 N/m) and mass (59.5 g) of the Ansys beams (E 48 GPa, A 5.235e-5 m^2,
  // rho 16840 kg/m^3 equivalent).
  static FromStepOptions apa95ml_beam();
  // data/geometry/apa300ml.geo: steel shell (210 GPa, nu 0.3, 7850 kg/m^3); remote points as in
  // the report's Fig. 4.1: top (1, y=max), bottom (2, y=min), stack_a (3, x=-30: the actuator
  // stacks' outer end), stack_b (5, x=30: the sensor stack's outer end); joint stack_mid (4) two
  // thirds of the way from stack_a to stack_b; stacks stack_a-stack_mid (the two actuator stacks,
  // 40 mm) and stack_mid-stack_b (the sensor stack, 20 mm) with Table 4.1's c^E and area; clamp bottom.
  static FromStepOptions apa300ml();
  // InputError naming the option for values out of range, repeated names, a material for an
  // unknown region, a region without material, a clamp that is not a remote point.
  void validate() const;
};

struct JointResult {
  std::string name;
  long node = -1;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
};

struct StackResult {
  std::string from, to;
  long node_a = -1, node_b = -1;
  double length_m = 0.0;
  double axial_stiffness = 0.0;  // N/m
  double mass = 0.0;             // kg
};

struct RemotePointResult {
  std::string name;
  FaceSelector selector;
  std::vector<int> surfaces;          // gmsh surface tags selected
  long node = -1;                     // REF NODE: the super element's node
  long rot_node = -1;                 // ROT NODE (its translations are the rotations)
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // area centroid of the faces
  double area_m2 = 0.0;
  Index face_nodes = 0;               // mesh nodes tied to the REF NODE
};

struct ToolInfo {
  std::string path;
  std::string version;
};

struct FromStepResult {
  SuperElement reduced;               // remote points (6 DOF each), then the modal DOF
  std::vector<RemotePointResult> remote_points;
  std::vector<JointResult> joints;
  std::vector<StackResult> stacks;
  MeshEstimate estimate;              // before meshing
  std::map<std::string, Index> region_elements;  // elements per region
  Index mesh_nodes = 0, mesh_elements = 0;
  std::string element_type;           // "C3D10" or "C3D4"
  Index model_dofs = 0;               // DOF of the ccx dump (rigid-body faces condensed)
  CraigBamptonResult reduction;       // statistics (its `reduced` is moved to `reduced` above)
  std::string clamp;                  // the remote point clamped below
  Eigen::VectorXd modes_clamped_Hz;   // reduced model, `clamp` fixed (first clamped_modes)
  Eigen::VectorXd free_modes_Hz;      // reduced model, free-free (first 6 + clamped_modes)
  // ccx *FREQUENCY on the full mesh, same boundary condition, without the stacks; compare with
  // shell_modes_clamped_Hz (the reduced model before the stacks are added).
  std::optional<Eigen::VectorXd> reference_modes_Hz;
  Eigen::VectorXd shell_modes_clamped_Hz;  // reduced model without the stacks, `clamp` fixed
  // Static stiffness at `axial` with `clamp` fixed (N/m), with and without the stacks; 0 when
  // no `axial` is asked.
  double axial_stiffness = 0.0, shell_axial_stiffness = 0.0;
  ToolInfo gmsh, ccx;
  std::vector<std::pair<std::string, double>> seconds;  // wall time per step
  std::vector<std::filesystem::path> files;            // written into the output folder
  std::filesystem::path work_dir;     // kept only with keep_temp (empty otherwise)
};

// Runs the chain. InputError (exit code 3) for: a missing or unusable gmsh/ccx (not found, no
// version, too old), a STEP file that does not exist or does not load (no volume), a region box
// that contains no part of the bodies, a selector that selects no face (the message lists the
// planar faces), gmsh or ccx failing on the model (their last error lines are quoted; the logs
// stay in `out`). NumericalError (exit code 4) from the reduction.
[[nodiscard]] FromStepResult superelement_from_step(const std::filesystem::path& step_file,
                                                    const FromStepOptions& options);

}  // namespace piezobench::fem
