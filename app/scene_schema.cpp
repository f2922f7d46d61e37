#include "app/scene_schema.h"

#include <string>
#include <utility>
#include <vector>

namespace meniscus::app {

namespace {

const std::vector<std::string> FLOW_TYPES = {"fluid",          "enright",    "normal_speed",
                                             "mean_curvature", "curl_noise", "rigid",
                                             "expression",     "none"};
const std::vector<std::string> NORMAL_SPEED_METHODS = {"face_offsetting", "vertex_normals"};
const std::vector<std::pair<std::string, tracker::MeanCurvatureIntegrator>>
    MEAN_CURVATURE_INTEGRATORS = {{"forward_euler", tracker::MeanCurvatureIntegrator::forward_euler},
                                  {"heun", tracker::MeanCurvatureIntegrator::heun}};
const std::vector<std::pair<std::string, tracker::CurvatureOperator>> CURVATURE_OPERATORS = {
    {"cotangent", tracker::CurvatureOperator::cotangent},
    {"quartic_fit", tracker::CurvatureOperator::quartic_fit}};
const std::vector<std::string> EXACT_TYPES = {"none", "two_sphere_normal_flow",
                                              "sphere_mean_curvature", "rigid_motion"};

/// Reads/describes an enum through its names (the first name is used for the reference).
template <typename V, typename Enum>
void enum_field(V& v, const char* key, Enum& value,
                const std::vector<std::pair<std::string, Enum>>& names, const char* meaning) {
    std::string text;
    std::vector<std::string> allowed;
    for (const auto& [name, e] : names) {
        allowed.push_back(name);
        if (e == value)
            text = name;
    }
    v.choice(key, text, allowed, meaning);
    for (const auto& [name, e] : names)
        if (name == text)
            value = e;
}

const std::vector<std::pair<std::string, fluid::BoundaryType>> BOUNDARY_TYPES = {
    {"free_slip", fluid::BoundaryType::free_slip},
    {"no_slip", fluid::BoundaryType::no_slip},
    {"inflow", fluid::BoundaryType::inflow},
    {"outflow", fluid::BoundaryType::outflow},
    {"periodic", fluid::BoundaryType::periodic}};
const char* const FACE_NAMES[3][2] = {{"x_min", "x_max"}, {"y_min", "y_max"}, {"z_min", "z_max"}};

template <typename V>
void visit_fields(V& v, fluid::FaceBoundary& o) {
    enum_field(v, "type", o.type, BOUNDARY_TYPES,
               "free_slip or no_slip wall, inflow (a prescribed velocity into the box), outflow "
               "(fixed pressure, zero-gradient velocity) or periodic (with the opposite face: the "
               "surface mesh wraps around the box too; needs /surface/shape, periodic along "
               "that axis, and no inflow or outflow face)");
    v.vec3("velocity", o.velocity, Range::any(), "m/s",
           "no_slip: the wall's velocity along itself (a moving wall; normal component 0)");
    v.number("pressure", o.pressure, Range::any(), "Pa", "outflow: the pressure on the face");
    v.section("inflow", "inflow: what flows in, where and how fast", [&](auto& r) {
        r.number("speed", o.inflow.speed, Range::non_negative(), "m/s",
                 "mean normal speed into the box over the region");
        r.number("pulse", o.inflow.pulse, Range{0.0, 1.0, false, true}, "",
                 "relative amplitude ε of a modulation of the speed, speed·(1 + ε sin 2πft): a "
                 "forced jet (0 = steady)");
        r.number("pulse_frequency", o.inflow.pulse_frequency, Range::non_negative(), "Hz",
                 "f of that modulation");
        enum_field(r, "profile", o.inflow.profile,
                   {{"uniform", fluid::InflowProfile::uniform},
                    {"parabolic", fluid::InflowProfile::parabolic}},
                   "uniform, or parabolic: zero at the region's rim on walls (disc: 2U(1 - r²/R²); "
                   "whole face: 3/2 U (1 - s²) across each axis walled on both sides)");
        enum_field(r, "region", o.inflow.region,
                   {{"face", fluid::InflowRegion::face}, {"disc", fluid::InflowRegion::disc}},
                   "the whole face, or a disc (a nozzle; the rest of the face is a no-slip wall)");
        r.vec3("centre", o.inflow.centre, Range::any(), "m",
               "disc: its centre (the coordinate along the face's normal is ignored)");
        r.number("radius", o.inflow.radius, Range::non_negative(), "m", "disc: its radius");
        enum_field(r, "phase", o.inflow.phase,
                   {{"liquid", fluid::InflowPhase::liquid}, {"gas", fluid::InflowPhase::gas}},
                   "what flows in");
    });
}

/// A face of /fluid/boundaries: a type name alone, or an object of visit_fields(FaceBoundary).
void face_field(JsonReader& r, const char* name, fluid::FaceBoundary& face, bool) {
    if (r.has(name) && r.raw(name).is_string()) {
        enum_field(r, name, face.type, BOUNDARY_TYPES, "");
        return;
    }
    r.section(name, "", [&](JsonReader& f) { visit_fields(f, face); });
}

/// The reference describes x_min alone (`described`); the other faces are alike.
void face_field(ReferenceWriter& r, const char* name, fluid::FaceBoundary& face, bool described) {
    if (described)
        r.section(name, "the x_min face; x_max, y_min, y_max, z_min and z_max alike",
                  [&](ReferenceWriter& f) { visit_fields(f, face); });
}

template <typename V>
void visit_fields(V& v, DomainOptions& o) {
    v.vec3("min", o.min, Range::any(), "m", "min corner of the fluid box");
    v.vec3("size", o.size, Range::positive(), "m", "edge lengths of the fluid box");
    v.integer("cells", o.cells, Range::between(2, 4096), "",
              "cells along x (cubic cells; y and z get size/dx rounded)");
}

template <typename V>
void visit_fields(V& v, fluid::FluidOptions& o) {
    enum_field(v, "mode", o.mode,
               {{"two_phase", fluid::FluidMode::two_phase},
                {"free_surface", fluid::FluidMode::free_surface}},
               "`two_phase` solves liquid and gas; `free_surface` treats the gas as void");
    v.vec3("gravity", o.gravity, Range::any(), "m/s²", "body acceleration");
    v.section("phases", "densities, viscosities, surface tension", [&](auto& r) {
        r.number("rho_liquid", o.phases.rho_liquid, Range::positive(), "kg/m³", "liquid density");
        r.number("rho_gas", o.phases.rho_gas, Range::positive(), "kg/m³", "gas density");
        r.number("mu_liquid", o.phases.mu_liquid, Range::non_negative(), "Pa·s",
                 "liquid viscosity");
        r.number("mu_gas", o.phases.mu_gas, Range::non_negative(), "Pa·s", "gas viscosity");
        r.number("sigma", o.phases.sigma, Range::non_negative(), "N/m",
                 "surface tension coefficient");
    });
    v.section("boundaries",
              "the six faces of the box (x_min, x_max, y_min, y_max, z_min, z_max): each a "
              "boundary type as a string (\"no_slip\") or an object like x_min's",
              [&](auto& r) {
                  for (int axis = 0; axis < 3; ++axis)
                      for (int side = 0; side < 2; ++side)
                          face_field(r, FACE_NAMES[axis][side], o.boundaries.face(axis, side),
                                     axis == 0 && side == 0);
              });
    enum_field(v, "advection", o.advection.scheme,
               {{"maccormack", fluid::AdvectionScheme::maccormack},
                {"bfecc", fluid::AdvectionScheme::bfecc},
                {"semi_lagrangian", fluid::AdvectionScheme::semi_lagrangian}},
               "velocity advection scheme");
    v.boolean("viscosity", o.viscosity.enabled, "implicit viscosity on/off");
    enum_field(v, "pressure_solver", o.pressure.solver,
               {{"multigrid_pcg", fluid::PressureSolver::multigrid_pcg},
                {"mic0_pcg", fluid::PressureSolver::mic0_pcg},
                {"eigen_ic_cg", fluid::PressureSolver::eigen_ic_cg},
                {"hypre_pfmg_pcg", fluid::PressureSolver::hypre_pfmg_pcg}},
               "pressure Poisson solver (hypre_pfmg_pcg: hypre's PCG with a PFMG V-cycle; under "
               "mpirun with several ranks hypre is always used)");
    v.number("pressure_tolerance", o.pressure.iteration.tolerance, Range{0.0, 1.0, true, true}, "",
             "relative residual of the pressure solve");
    v.integer("pressure_max_iterations", o.pressure.iteration.max_iterations,
              Range::between(1, 100000), "", "PCG iterations before a pressure solve gives up");
    v.boolean("pressure_single_precision", o.pressure.multigrid.single_precision,
              "multigrid_pcg: run the V-cycles in float (the CG around them stays in double; "
              "same iterations and accuracy, half the smoother's memory traffic)");
    v.number("viscosity_tolerance", o.viscosity.iteration.tolerance, Range{0.0, 1.0, true, true},
             "", "relative residual of the implicit viscosity solve");
    enum_field(v, "viscosity_weights", o.viscosity.weights,
               {{"sharp", fluid::ViscosityWeights::sharp},
                {"volume_fraction", fluid::ViscosityWeights::volume_fraction},
                {"pointwise", fluid::ViscosityWeights::pointwise}},
               "two_phase μ next to the interface: `sharp` (cell phase, harmonic mean on edges), "
               "`volume_fraction` (blended by the liquid fraction of each control volume) or "
               "`pointwise` (the phase at each cell centre and edge midpoint)");
    enum_field(v, "viscosity_preconditioner", o.viscosity.preconditioner,
               {{"multigrid", fluid::ViscousPreconditioner::multigrid},
                {"jacobi", fluid::ViscousPreconditioner::jacobi},
                {"jacobi_surface", fluid::ViscousPreconditioner::jacobi_surface},
                {"hypre_pfmg", fluid::ViscousPreconditioner::hypre_pfmg}},
               "preconditioner of the viscous CG: a V-cycle per velocity component's block "
               "(`multigrid` our own, `hypre_pfmg` hypre's PFMG, which also runs on several "
               "ranks), the diagonal, or `jacobi_surface`: the diagonal plus "
               "/coupling/implicit_tension's surface term, inverted exactly (3x fewer iterations "
               "at 10x the capillary limit, but a sparse LU each step)");
    v.integer("viscosity_max_iterations", o.viscosity.iteration.max_iterations,
              Range::between(1, 100000), "", "CG iterations before a viscosity solve gives up");
    v.boolean("viscosity_single_precision", o.viscosity.multigrid.single_precision,
              "viscosity_preconditioner multigrid: run the V-cycles in float (the CG around them "
              "stays in double)");
    v.section("viscous_pressure", "how the viscous and pressure solves are coupled in a step",
              [&](auto& r) {
                  enum_field(r, "coupling", o.viscous_pressure.coupling,
                             {{"coupled", fluid::ViscousPressureCoupling::coupled},
                              {"incremental", fluid::ViscousPressureCoupling::incremental},
                              {"split", fluid::ViscousPressureCoupling::split}},
                             "`coupled`: the backward-Euler Stokes step (Uzawa passes of "
                             "viscous and pressure solves); `incremental`: previous pressure in "
                             "the viscous solve, one projection (steady states right but reached "
                             "slowly at large νΔt/Δx²); `split`: viscosity, then projection "
                             "(steady states depend on the time step)");
                  enum_field(r, "preconditioner", o.viscous_pressure.preconditioner,
                             {{"poisson_solve", fluid::SchurPreconditioner::poisson_solve},
                              {"v_cycle", fluid::SchurPreconditioner::v_cycle}},
                             "coupled: the Cahouet–Chabard preconditioner's inverse pressure "
                             "Laplacian, a full `poisson_solve` or one multigrid `v_cycle` "
                             "(multigrid_pcg only)");
                  r.integer("max_passes", o.viscous_pressure.max_passes, Range::between(1, 100),
                            "", "coupled: most viscous + pressure passes per step");
                  r.number("pass_tolerance", o.viscous_pressure.pass_tolerance,
                           Range{0.0, 1.0, true, true}, "",
                           "coupled: the passes stop once D/(1+D) times the largest "
                           "divergence·Δx of the viscous velocity, over the largest speed, is "
                           "below this (D = νΔt/Δx² of the more diffusive phase)");
                  r.boolean("local_passes", o.viscous_pressure.local_passes,
                            "coupled: run the passes on the box of the cells whose own "
                            "estimate exceeds pass_tolerance (the interface and gas of a water-"
                            "air flow), grown by pass_margin cells, when it is at most half the "
                            "grid (one process, no periodic axis, no inflow or outflow face, "
                            "explicit tension)");
                  r.integer("pass_margin", o.viscous_pressure.pass_margin, Range::between(0, 1000),
                            "cells", "coupled: cells added on every side of the passes' box");
              });
    v.number("cfl_number", o.time_step.cfl_number, Range::positive(), "cells",
             "cells a fluid particle may cross per step");
    v.number("max_dt", o.time_step.max_dt, Range::positive(), "s",
             "upper bound on the fluid's time step (/time/dt caps it too)");
}

template <typename V>
void visit_fields(V& v, CouplingOptions& o) {
    v.number("edge_length_cells", o.edge_length_cells, Range::non_negative(), "cells",
             "tracker edge length in grid cells (0 = use /surface/edge_length)");
    v.boolean("volume_correction", o.simulation.volume_correction,
              "restore each connected component's volume every step (followed through merges)");
    v.integer("curvature_smoothing", o.simulation.surface_tension.smoothing_passes,
              Range::between(0, 20), "", "one-ring averaging passes over vertex curvature");
    v.number("subgrid_rate", o.simulation.surface_tension.subgrid_rate, Range::between(0.0, 0.2),
             "", "damping rate β of mesh-scale wrinkles the grid cannot resolve (0 = off)");
    v.integer("subgrid_filter_order", o.simulation.surface_tension.subgrid_filter_order,
              Range::between(1, 3), "",
              "order m of the sub-grid high-pass (I − S)^m; a resolved wave feels ε^m of the damping");
    v.number("max_curvature_cells", o.simulation.surface_tension.max_curvature_cells,
             Range::positive(), "1/cells",
             "largest |κ| a crossed face takes, in 1/Δx (a degenerate vertex's curvature has no "
             "bound)");
    enum_field(v, "velocity_interpolation", o.simulation.interpolate.method,
               {{"trilinear", coupling::VelocityInterpolation::trilinear},
                {"quadratic_bspline", coupling::VelocityInterpolation::quadratic_bspline},
                {"one_sided", coupling::VelocityInterpolation::one_sided}},
               "grid → vertex velocity reconstruction");
    enum_field(v, "outside_velocity", o.simulation.interpolate.outside,
               {{"clamp", coupling::OutsideVelocity::clamp},
                {"mirror", coupling::OutsideVelocity::mirror}},
               "velocity of mesh vertices outside the domain: clamp (that of the nearest point "
               "inside) or mirror (across free-slip walls, the reflected flow)");
    v.number("outflow_clip_near_cells", o.simulation.open_boundaries.clip_near_cells,
             Range::non_negative(), "cells",
             "the mesh beyond an outflow face is cut off between this many cells beyond the face "
             "and outflow_clip_far_cells (where the vertices leave most room)");
    v.number("outflow_clip_far_cells", o.simulation.open_boundaries.clip_far_cells,
             Range::positive(), "cells", "the far end of that range (> outflow_clip_near_cells)");
    v.number("capillary_safety", o.simulation.capillary_safety,
             Range{0.0, coupling::MAX_IMPLICIT_CAPILLARY_SAFETY, true, false}, "",
             "factor on the capillary time-step limit (above 1 only with implicit_tension)");
    v.number("implicit_tension", o.simulation.implicit_tension, Range::between(0.0, 1.0), "",
             "semi-implicit surface tension: the fraction θ of the step ahead at which the "
             "surface's tension is taken, a surface viscosity θσΔt in the viscous solve (0 = "
             "explicit; 1 is the validated value, 0.5 went unstable at 3× the limit); needs "
             "velocity_interpolation trilinear");
    enum_field(
        v, "implicit_tension_form", o.simulation.implicit_tension_form,
        {{"normal", coupling::SurfaceTermForm::normal}, {"full", coupling::SurfaceTermForm::full}},
        "the implicit term's surface stiffness: normal (damps the velocity's normal "
        "component's gradient: shape changes only) or full (Hysing's, all three components: "
        "it damps the surface's stretching too, which keeps films between bubbles from "
        "draining)");
}

template <typename V>
void visit_fields(V& v, SurfaceOptions& o) {
    v.number("edge_length", o.edge_length, Range::positive(), "m",
             "requested mean edge length ξ of the mesh generated from `shape`");
    v.text("mesh_file", o.mesh_file,
           "OBJ or PLY file with the initial surface (relative to the scene file); "
           "closed, consistently oriented, no degenerate or duplicate triangles");
    v.integer("remesh_iterations", o.remesh_iterations, Range::between(0, 100), "",
              "isotropic remeshing passes after marching tetrahedra");
    v.section("crease", "refinement around the shape's creases after meshing", [&](auto& r) {
        r.integer("levels", o.crease.levels,
                  Range::between(0, tracker::CreaseRefinementOptions::MAX_LEVELS), "",
                  "edge halvings near creases (0 = off)");
        r.number("angle", o.crease.angle, Range{0.0, M_PI, true, true}, "rad",
                 "an edge whose end normals turn by more than this crosses a crease");
        r.number("band", o.crease.band, Range::non_negative(), "m",
                 "refine within this distance of a crease (0 = twice edge_length)");
        r.boolean("snap", o.crease.snap,
                  "before refining, move vertices onto the creases and flip edges to run along "
                  "them (sharp edges become mesh edges instead of chamfers; needs angle < π/2)");
    });
    v.boolean("open", o.open,
              "the mesh_file is an open surface with boundary edges (paper §4.4; geometric flows "
              "only): boundary edges are never split, flipped, collapsed or merged");
    v.choice("inside", o.inside, {"liquid", "gas"},
             "phase enclosed by the surface: `liquid` (drops, pools) or `gas` (bubbles; the "
             "liquid fills everything outside)");
}

template <typename V>
void visit_fields(V& v, tracker::FaceOffsettingOptions& o) {
    enum_field(v, "weighting", o.weighting,
               {{"area", tracker::OffsetWeighting::area},
                {"angle", tracker::OffsetWeighting::angle}},
               "weights of the incident triangle planes: area or interior angle at the vertex");
    enum_field(v, "expansion", o.expansion,
               {{"huygens", tracker::ExpansionRule::huygens},
                {"planes", tracker::ExpansionRule::planes}},
               "where offset planes diverge: `huygens` (mean offset along the mean normal, the "
               "exact expansion fan) or `planes` (least-squares plane intersection, Jiao)");
    v.number("primary_eigenvalue_ratio", o.primary_eigenvalue_ratio, Range{0.0, 1.0, true, true},
             "", "eigenvalues ≥ this ratio of the largest span the primary space (Jiao's ε)");
    v.number("null_space_smoothing", o.null_space_smoothing, Range::between(0.0, 1.0), "",
             "fraction of the tangential (null-space) smoothing move added per step");
    v.number("max_offset_ratio", o.max_offset_ratio, Range::at_least(1.0), "",
             "cap on a vertex's offset in units of its largest incident plane offset");
}

template <typename V>
void visit_fields(V& v, NormalSpeedOptions& o) {
    v.choice("method", o.method, NORMAL_SPEED_METHODS,
             "`face_offsetting` (entropy solution, paper §4.1) or `vertex_normals` (area-weighted "
             "vertex normals; the paper's non-converging comparison, Fig. 4.2)");
    v.number("speed", o.speed, Range::any(), "m/s",
             "normal speed, positive along the outward normal (expands a closed surface)");
    v.number("reversal_time", o.reversal_time, Range::non_negative(), "s",
             "the speed flips sign at this time (A1: 1); 0 = never");
    v.number("min_area_fraction", o.inversion.min_area_fraction, Range{0.0, 1.0, false, true}, "",
             "steps are shortened so every triangle keeps this fraction of its area along its "
             "normal (no inversion)");
    v.section("face_offsetting", "face-offsetting scheme (method face_offsetting)",
              [&](auto& r) { visit_fields(r, o.face_offsetting); });
}

template <typename V>
void visit_fields(V& v, tracker::CurlNoiseOptions& o) {
    int seed = static_cast<int>(o.seed);
    v.integer("seed", seed, Range::between(0, std::numeric_limits<int>::max()), "",
              "pseudorandom seed (the same seed gives the same field on every platform)");
    o.seed = static_cast<std::uint64_t>(seed);
    v.boolean("planar", o.planar,
              "potential (0, 0, φ): motion in planes z = const (paper §4.3's rotation)");
    v.number("rms_speed", o.rms_speed, Range::positive(), "m/s", "spatial RMS of the speed");
    v.number("base_wavelength", o.base_wavelength, Range::positive(), "m",
             "wavelength of the first octave");
    v.integer("octaves", o.octaves, Range::between(1, 16), "", "octaves of random Fourier modes");
    v.integer("modes_per_octave", o.modes_per_octave, Range::between(1, 10000), "",
              "random modes per octave");
    v.number("lacunarity", o.lacunarity, Range::at_least(1.0), "",
             "wavelength divisor per octave");
    v.number("persistence", o.persistence, Range::positive(), "",
             "velocity amplitude factor per octave");
    v.number("time_frequency", o.time_frequency, Range::non_negative(), "rad/s",
             "mode angular frequencies drawn from [−f, f] (0 = steady field)");
}

template <typename V>
void visit_fields(V& v, ExactSolutionOptions& o) {
    v.choice("type", o.type, EXACT_TYPES,
             "`two_sphere_normal_flow` (A1: needs /flow/type normal_speed with speed > 0) or "
             "`sphere_mean_curvature` (needs /flow/type mean_curvature); the initial surface must "
             "be that shape (checked when the run starts); or `rigid_motion` (needs /flow/type "
             "rigid; any surface: the initial one carried by the exact rigid map, compared both "
             "ways, with the symmetric Hausdorff distance in `hausdorff`)");
    v.vec3("center0", o.center0, Range::any(), "m", "first sphere's centre (the sphere's centre)");
    v.vec3("center1", o.center1, Range::any(), "m", "second sphere's centre (two spheres only)");
    v.number("radius", o.radius, Range::positive(), "m", "initial radius of the sphere(s)");
    v.integer("triangle_subdivisions", o.sampling.triangle_subdivisions, Range::between(1, 64), "",
              "m: the error samples m² points per triangle");
}

template <typename V>
void visit_fields(V& v, FlowOptions& o) {
    v.choice("type", o.type, FLOW_TYPES,
             "what moves the surface: `fluid` (coupled Navier–Stokes), `enright` (paper §4.3 "
             "deformation test, RK4), `normal_speed` (§4.1), `mean_curvature` (§4.2, CFL-limited "
             "forward Euler or Heun), `curl_noise` (§4.3, RK4), `rigid` (rotation and "
             "translation, RK4), `expression` (a user's analytic field, RK4), `none`");
    v.number("period", o.period, Range::positive(), "s",
             "Enright period T; the field is modulated by sin(2πt/T)");
    v.section("normal_speed", "motion in the normal direction (type normal_speed)",
              [&](auto& r) { visit_fields(r, o.normal_speed); });
    v.section("mean_curvature", "motion by mean curvature (type mean_curvature)", [&](auto& r) {
        r.number("cfl_number", o.mean_curvature.cfl_number, Range{0.0, 1.0, true, false}, "",
                 "step ≤ cfl_number · (shortest edge)², also capped by /time/dt");
        enum_field(r, "integrator", o.mean_curvature.integrator, MEAN_CURVATURE_INTEGRATORS,
                   "`forward_euler` (the paper's) or `heun` (second order in time, two curvature "
                   "evaluations per step, same stability limit)");
        enum_field(r, "curvature_operator", o.mean_curvature.curvature_operator,
                   CURVATURE_OPERATORS,
                   "`cotangent` (Meyer et al., the paper's) or `quartic_fit` (κ n of a quartic "
                   "height field fitted through each vertex over its two-ring, pointwise fourth "
                   "order on smooth patches; the cotangent formula where the fit turns by more "
                   "than fit_max_turn)");
        r.number("fit_max_turn", o.mean_curvature.fit_max_turn, Range::positive(), "rad",
                 "quartic_fit: largest turn of the fitted two-ring for its curvature to be used");
        r.boolean("fit_sphere_refit", o.mean_curvature.fit_sphere_refit,
                  "quartic_fit: refit each quartic as h = p + c·h² with c = −κ/4 from the first "
                  "fit, exact on spheres (false: the single fit, whose κ is slightly too small)");
    });
    v.section("curl_noise", "divergence-free pseudorandom field (type curl_noise)",
              [&](auto& r) { visit_fields(r, o.curl_noise); });
    v.section("rigid", "rigid rotation and translation (type rigid), advected by RK4",
              [&](auto& r) {
                  r.vec3("angular_velocity", o.rigid.angular_velocity, Range::any(), "rad/s",
                         "ω: rotation axis times rate, right-handed; u = v + ω × (x − c(t))");
                  r.vec3("center", o.rigid.center, Range::any(), "m",
                         "c₀: centre of rotation at t = 0");
                  r.vec3("velocity", o.rigid.velocity, Range::any(), "m/s",
                         "v: translation; the centre moves with it, c(t) = c₀ + v t");
              });
    v.section("expression",
              "a user's analytic velocity field (type expression), advected by RK4", [&](auto& r) {
                  r.text3("velocity", o.expression.velocity,
                          "u, v, w as expressions in x, y, z (m), t (s), `pi` and `constants`: "
                          "numbers, + - * / ^ (right-associative; -x^2 = -(x^2)), parentheses, "
                          "sin cos tan asin acos atan sinh cosh tanh exp log log10 sqrt abs floor "
                          "ceil sign, atan2(y, x) pow(a, b) mod(a, b), min(a, b, …) max(a, b, …); "
                          "e.g. `[\"-2*pi*(y-0.5)\", \"2*pi*(x-0.5)\", 0]`");
                  r.number_map("constants", o.expression.constants, "",
                               "named numbers the expressions may use, e.g. `{\"omega\": 6.28}`");
              });
    v.section("exact", "exact solution whose error is recorded in stats.jsonl every frame",
              [&](auto& r) { visit_fields(r, o.exact); });
}

template <typename V>
void visit_fields(V& v, TimeOptions& o) {
    v.number("end", o.end, Range::positive(), "s", "simulated end time");
    v.integer("frames", o.frames, Range::between(1, 1000000), "",
              "frames after the initial one, evenly spaced in time");
    v.number("dt", o.dt, Range::positive(), "s",
             "maximum time step (shortened to land exactly on frame times); fluid scenes take the "
             "smaller of it and /fluid/max_dt");
    v.boolean("land_on_frames", o.land_on_frames,
              "shorten steps to end exactly on frame times; false (geometric flows only): a frame "
              "is written after the first step that reaches its time, so the steps are those of "
              "`meniscus validate` (the end time is still hit exactly)");
}

template <typename V>
void visit_fields(V& v, OutputOptions& o) {
    v.boolean("ply", o.ply, "write surface_NNNN.ply (binary little-endian)");
    v.boolean("ply_velocity", o.ply_velocity, "include per-vertex velocity vx, vy, vz in the PLY");
    v.boolean("obj", o.obj, "also write surface_NNNN.obj");
    v.boolean("vdb", o.vdb,
              "write fields_NNNN.vdb with grids `surface` (level set) and `density` (fog)");
    v.number("voxel_size", o.voxel_size, Range::non_negative(), "m",
             "VDB voxel size; 0 = half of /surface/edge_length");
    v.number("half_width_voxels", o.half_width_voxels, Range::at_least(1.0), "voxels",
             "narrow-band half width of the `surface` level set");
    v.number("density_ramp_voxels", o.density_ramp_voxels, Range::positive(), "voxels",
             "width of the `density` step across the surface (0.5 on the surface, 1 inside, "
             "0 outside); at most 2 · half_width_voxels");
    v.boolean("vdb_velocity", o.vdb_velocity,
              "fluid scenes: write the grid `vel` (cell-centred velocity) into the VDB");
    v.boolean("vdb_pressure", o.vdb_pressure,
              "fluid scenes: write the grid `pressure` (Pa, cell-centred) into the VDB");
    v.choice("length_unit", o.length_unit, {"m", "cm", "mm"},
             "unit of every length written: PLY/OBJ positions and velocities (unit/s), VDB "
             "transforms, distances and `vel`; recorded in meniscus.json (stats.jsonl stays SI)");
    v.integer("checkpoint_every", o.checkpoint_every, Range::between(0, 1000000), "frames",
              "write checkpoint.bin (everything `meniscus run --resume` needs to continue the run "
              "exactly) with every Nth frame and the last; 0 = never");
}

template <typename V>
void visit_fields(V& v, tracker::CollisionOptions& o) {
    v.boolean("repulsion", o.repulsion, "proximity repulsion impulses before CCD (paper §3.8)");
    v.integer("impulse_sweeps", o.impulse_sweeps, Range::between(0, 100), "",
              "sweeps of individual CCD impulses before impact zones (paper: 3)");
    v.integer("max_impact_zone_iterations", o.max_impact_zone_iterations, Range::between(1, 10000),
              "", "bound on impact-zone detect/solve rounds");
    v.integer("max_rigid_zone_iterations", o.max_rigid_zone_iterations, Range::between(0, 10000),
              "", "bound on rigid impact-zone rounds (fallback)");
    v.integer("max_step_shortenings", o.max_step_shortenings, Range::between(0, 60), "",
              "halvings of the motion tried before the mesh is left in place (last fallback)");
    v.integer("max_zone_matrix_entries", o.max_zone_matrix_entries,
              Range::between(1, 2'000'000'000), "",
              "largest impact-zone matrix assembled (entries, 16 bytes each); larger zones move "
              "rigidly");
    v.boolean("preserve_volume", o.preserve_volume,
              "volume-aware response (not in the paper): each closed component gets back the "
              "volume collision handling changed, through the vertices it left alone; kept only "
              "when CCD verifies the corrected motion");
    v.integer("max_volume_rounds", o.max_volume_rounds, Range::between(1, 100), "",
              "attempts of that correction; each one CCD rejects leaves the vertices of its "
              "collisions out of the next");
}

template <typename V>
void visit_fields(V& v, tracker::RemeshOptions& o) {
    v.boolean("split", o.split, "split edges longer than α (§3.5.1)");
    v.boolean("flip", o.flip, "flip non-Delaunay edges (§3.5.2)");
    v.boolean("collapse", o.collapse, "collapse edges shorter than β (§3.5.3)");
    v.boolean("smooth", o.smooth, "null-space smoothing (§3.6.1)");
    v.number("max_edge_fraction", o.max_edge_fraction, Range::positive(), "ξ",
             "α: maximum edge length");
    v.number("min_edge_fraction", o.min_edge_fraction, Range::positive(), "ξ",
             "β: minimum edge length");
    v.number("max_volume_change_fraction", o.max_volume_change_fraction, Range::positive(), "ξ³",
             "γ: largest volume change of one flip or collapse");
    v.number("curvature_edge_fraction", o.curvature_edge_fraction, Range::non_negative(),
             "radians",
             "curvature-adaptive sizing (not in the paper; A2 uses 0.7; needs "
             "split_on_fitted_surface): where the surface has curvature κ, α and β shrink so edges "
             "turn by at most this angle (α·s, β·s with s = min(1, c/(κα))); 0 keeps α and β");
    v.boolean("curvature_sizing_convex_only", o.curvature_sizing_convex_only,
              "curvature-adaptive sizing refines only where the surface is convex (largest "
              "positive principal curvature): tips and necks, not concave creases");
    v.number("min_curvature_size_fraction", o.min_curvature_size_fraction,
             Range{0.0, 1.0, true, false}, "",
             "smallest factor s of curvature-adaptive and thin-sheet sizing (α and β never fall "
             "below s·α, s·β)");
    v.number("thin_sheet_sag_fraction", o.thin_sheet_sag_fraction, Range::non_negative(), "",
             "experimental thin-sheet sizing (not in the paper; needs split_on_fitted_surface): "
             "where a vertex faces an opposite-facing part of the surface at distance h, α and β "
             "shrink until the chord sag of edges there is at most this fraction of h; 0 is off");
    v.integer("max_split_passes", o.max_split_passes, Range::between(1, 100), "",
              "sweeps over long edges per step");
    v.integer("max_collapse_passes", o.max_collapse_passes, Range::between(1, 100), "",
              "sweeps over short edges per step");
    v.integer("max_flip_sweeps", o.max_flip_sweeps, Range::between(1, 100), "",
              "flip sweeps per step (paper: 5)");
    v.number("min_flip_length_decrease_fraction", o.min_flip_length_decrease_fraction,
             Range{0.0, 1.0, false, true}, "", "a flip must shorten the edge by this fraction");
    v.integer("collapse_position_attempts", o.collapse_position_attempts, Range::between(1, 100),
              "", "collapse trajectories tried from the butterfly position towards the midpoint");
    v.number("max_normal_change_degrees", o.max_normal_change_degrees,
             Range{0.0, 180.0, true, false}, "degrees",
             "largest triangle normal change allowed by a collapse or flip");
    v.number("ridge_eigenvalue_ratio", o.ridge_eigenvalue_ratio, Range{0.0, 1.0, true, true}, "",
             "quadric metric λ₂/λ₁ above which a vertex is on a ridge");
    v.number("corner_eigenvalue_ratio", o.corner_eigenvalue_ratio, Range{0.0, 1.0, true, true}, "",
             "quadric metric λ₃/λ₁ above which a vertex is a corner");
    v.integer("smoothing_iterations", o.smoothing_iterations, Range::between(0, 100), "",
              "null-space smoothing steps per improvement");
    v.number("smoothing_step_fraction", o.smoothing_step_fraction, Range{0.0, 1.0, true, false}, "",
             "fraction of the smoothing displacement applied per step");
    v.boolean("split_on_fitted_surface", o.split_on_fitted_surface,
              "put split vertices on a fitted quadratic surface or circular arc instead of the "
              "butterfly point (more accurate shape; gains volume on the Enright test)");
    v.boolean("collapse_on_fitted_surface", o.collapse_on_fitted_surface,
              "collapses aim the merged vertex at the fitted-surface or circular-arc point a "
              "split of the edge would use instead of the butterfly point (shrinking shapes keep "
              "their vertices on the surface)");
    v.boolean(
        "smoothing_onto_fitted_surface", o.smoothing_onto_fitted_surface,
        "smoothing moves smooth vertices along a fitted surface (smoothing_fit_degree) instead of "
        "volume-neutrally in the tangent plane (more accurate shape; not volume-neutral)");
    v.integer("smoothing_fit_degree", o.smoothing_fit_degree, Range::between(2, 3), "",
              "degree of the height field smoothing_onto_fitted_surface fits over each vertex's "
              "two-ring: 3 keeps vertices drifting across a surface of varying curvature on it; "
              "2 is a quadratic");
    v.number("smoothing_fit_max_turn", o.smoothing_fit_max_turn, Range::non_negative(), "radians",
             "with smoothing_onto_fitted_surface, fitted moves only where the fit turns by at most "
             "this over its two-ring (radius × largest curvature); elsewhere, and where no fit is "
             "found, the tangent-plane move; 0: no bound");
    v.boolean("collapse_preserves_volume", o.collapse_preserves_volume,
              "collapses lift the new vertex until the enclosed volume is kept exactly (off: it "
              "stays at the butterfly point, on the smooth surface; shrinking shapes then keep "
              "their vertices on the surface instead of drifting outwards)");
    v.boolean("smoothing_holds_colliding_vertices", o.smoothing_holds_colliding_vertices,
              "with collision safety, a smoothing move that may collide keeps its vertices in "
              "place instead of pushing the other sheet away (keeps the volume of thin folded "
              "sheets)");
}

template <typename V>
void visit_fields(V& v, tracker::TopologyOptions& o) {
    v.boolean("allow_merging", o.allow_merging, "zipper proximal edge pairs (§3.7)");
    v.boolean("allow_separation", o.allow_separation,
              "remove degenerate tetrahedra and split singular vertices (§3.6)");
    v.number("merge_distance_fraction", o.merge_distance_fraction, Range::positive(), "ξ",
             "edge pairs closer than this merge (must exceed /tracker/proximity_fraction)");
    v.integer("max_zipper_alignments", o.max_zipper_alignments, Range::between(1, 4), "",
              "closed-form zipper alignments tried per pair");
    v.number("merge_spacing_fraction", o.merge_spacing_fraction, Range::non_negative(), "ξ",
             "within one step, pairs closer than this to a merge already made wait (0 = none)");
    v.section("separation", "separation of pinched surfaces", [&](auto& r) {
        r.number("nudge_fraction", o.separation.nudge_fraction, Range{0.0, 0.5, true, true}, "",
                 "copies of a singular vertex move this fraction towards their fan's centroid");
        r.integer("max_nudge_halvings", o.separation.max_nudge_halvings, Range::between(0, 60), "",
                  "halvings of the nudge tried when the nudged fans would intersect");
    });
}

template <typename V>
void visit_fields(V& v, tracker::TrackerOptions& o) {
    v.boolean("improve_mesh", o.improve_mesh, "mesh improvement on/off (paper §3.3 switch)");
    v.boolean("allow_topology_changes", o.allow_topology_changes,
              "merging and pinch-off on/off (paper §3.3 switch)");
    v.boolean("collision_safety", o.collision_safety,
              "keep the mesh intersection-free (paper §3.3 switch; off shows why it exists)");
    v.number("characteristic_length", o.characteristic_length, Range::non_negative(), "m",
             "ξ, which every length fraction multiplies; 0 = the initial mesh's mean edge length "
             "(the unrefined one with /surface/crease); set it to restart from a saved frame "
             "at the original resolution");
    v.number("proximity_fraction", o.proximity_fraction, Range::positive(), "ξ",
             "repulsion distance ε_p as a fraction of the initial mean edge length ξ");
    v.boolean("verify_intersection_free", o.verify_intersection_free,
              "run the exact static self-intersection test after every step and report it");
    v.section("collision", "collision resolution bounds",
              [&](auto& r) { visit_fields(r, o.collision); });
    v.section("remesh", "mesh improvement", [&](auto& r) { visit_fields(r, o.remesh); });
    v.section("topology", "topology changes", [&](auto& r) { visit_fields(r, o.topology); });
}

template <typename V>
void visit_fields(V& v, Scene& s) {
    v.text("name", s.name, "scene name, used in logs");
    v.text("description", s.description, "free text");
    v.section("surface", "the initial surface: `shape` (implicit) or `mesh_file`", [&](auto& r) {
        visit_fields(r, s.surface);
        r.known("shape");  // the shape tree is parsed by parse_shape()
    });
    v.section("tracker", "the explicit surface tracker",
              [&](auto& r) { visit_fields(r, s.tracker); });
    v.section("flow", "the velocity field that moves the surface",
              [&](auto& r) { visit_fields(r, s.flow); });
    v.section("domain", "the fluid box (fluid scenes)",
              [&](auto& r) { visit_fields(r, s.domain); });
    v.section("fluid", "the Navier–Stokes solver (fluid scenes)",
              [&](auto& r) { visit_fields(r, s.fluid); });
    v.section("coupling", "mesh ↔ grid coupling (fluid scenes)",
              [&](auto& r) { visit_fields(r, s.coupling); });
    v.known("initial_velocity");  // array of {shape, velocity}, parsed by parse_velocity_regions()
    v.section("time", "simulated time and frames", [&](auto& r) { visit_fields(r, s.time); });
    v.section("output", "per-frame files", [&](auto& r) { visit_fields(r, s.output); });
}

}  // namespace

void read_scene_fields(JsonReader& reader, Scene& scene) {
    visit_fields(reader, scene);
}

void describe_scene_fields(ReferenceWriter& writer, Scene& defaults) {
    visit_fields(writer, defaults);
}

}  // namespace meniscus::app
