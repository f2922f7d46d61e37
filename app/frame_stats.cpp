#include "app/frame_stats.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "tracker/mesh_measures.h"

namespace meniscus::app {

using tracker::SurfaceMesh;

namespace {

/// The surface's part of both kinds of line: its counts and volumes (m³), total and per component.
/// (nlohmann::json keeps an object's keys sorted, so merging it changes no line's text.)
nlohmann::json surface_stats(const SurfaceMesh& mesh) {
    const auto components = tracker::triangle_components(mesh);
    const std::vector<double> volumes = tracker::component_volumes(mesh, components);
    double total = 0.0;
    for (double v : volumes)
        total += v;
    return {{"vertices", mesh.count_live_vertices()},
            {"triangles", mesh.count_live_triangles()},
            {"components", components.count},
            {"volume", total},
            {"component_volumes", volumes}};
}

}  // namespace

nlohmann::json frame_stats(int frame, double time, double dt, long long steps,
                           const SurfaceMesh& mesh, const FrameWork& work) {
    const auto edges = tracker::edge_length_stats(mesh);
    const auto angles = tracker::angle_stats(mesh);
    nlohmann::json line = {{"frame", frame},
                           {"time", time},
                           {"dt", dt},
                           {"steps", steps},
                           {"mean_edge_length", edges.mean},
                           {"min_angle_degrees", angles.min_degrees},
                           {"max_angle_degrees", angles.max_degrees},
                           {"collisions_found", work.collisions_found},
                           {"impact_zone_iterations", work.impact_zone_iterations},
                           {"step_shortenings", work.step_shortenings},
                           {"flow_step_shortenings", work.flow_shortenings},
                           {"intersecting_pairs", work.intersecting_pairs},
                           {"volume_change_by_phase",
                            {{"remeshing", work.volume_remeshing},
                             {"motion", work.volume_motion},
                             {"collisions", work.volume_collisions}}},
                           {"seconds",
                            {{"improvement", work.improvement},
                             {"topology", work.topology},
                             {"set_velocity", work.set_velocity},
                             {"collisions", work.collisions},
                             {"output", work.output}}}};
    line.update(surface_stats(mesh));
    return line;
}

void FluidFrameTimes::add(const coupling::SimulationStepReport& step) {
    coupled += step.timings;
    fluid += step.fluid.timings;
}

nlohmann::json FluidFrameTimes::json() const {
    const auto figures = [&](double PhaseSeconds::*part) {
        return nlohmann::json{{"rasterize", coupled.rasterize.*part},
                              {"curvature", coupled.curvature.*part},
                              {"fluid", coupled.fluid.*part},
                              {"fluid_phases",
                               {{"advection", fluid.advection.*part},
                                {"forces", fluid.forces.*part},
                                {"viscosity", fluid.viscosity.*part},
                                {"pressure_build", fluid.pressure_build.*part},
                                {"pressure_solve", fluid.pressure_solve.*part},
                                {"extrapolation", fluid.extrapolation.*part}}},
                              {"interpolate", coupled.interpolate.*part},
                              {"volume_correction", coupled.volume_correction.*part},
                              {"tracker", coupled.tracker.*part},
                              {"output", output.*part}};
    };
    nlohmann::json seconds = figures(&PhaseSeconds::wall);
    seconds["cpu"] = figures(&PhaseSeconds::cpu);
    return seconds;
}

void FrameSolves::add(const fluid::StepResult& r) {
    pressure_iterations += r.pressure.iterations;
    viscosity_iterations += r.viscosity.iterations;
    passes += r.passes;
    pressure_residual = std::max(pressure_residual, r.pressure.residual);
    viscosity_residual = std::max(viscosity_residual, r.viscosity.residual);
    pass_change = std::max(pass_change, r.pass_change);
    pressure_failures += r.pressure.converged ? 0 : 1;
    viscosity_failures += r.viscosity.converged ? 0 : 1;
    pass_failures += r.converged_passes ? 0 : 1;
    if (r.passes > 0) {
        pass_cells += static_cast<double>(r.pass_cells);
        ++steps_with_passes;
    }
}

nlohmann::json FrameSolves::json(long long steps) const {
    const double n = static_cast<double>(std::max<long long>(steps, 1));
    return {{"pressure",
             {{"iterations_per_step", pressure_iterations / n},
              {"max_residual", pressure_residual},
              {"unconverged_steps", pressure_failures}}},
            {"viscosity",
             {{"iterations_per_step", viscosity_iterations / n},
              {"max_residual", viscosity_residual},
              {"unconverged_steps", viscosity_failures}}},
            {"viscous_pressure_passes",
             {{"per_step", passes / n},
              {"max_change", pass_change},
              {"unconverged_steps", pass_failures},
              // Cells per step with passes: their region's (local_passes) or the grid's.
              {"mean_cells",
               pass_cells / static_cast<double>(std::max<long long>(steps_with_passes, 1))}}}};
}

std::string FrameSolves::warning(int frame, long long steps) const {
    if (pressure_failures == 0 && viscosity_failures == 0 && pass_failures == 0)
        return "";
    std::ostringstream s;
    s << "warning: frame " << frame << ":";
    if (pressure_failures > 0)
        s << " the pressure solve did not converge in " << pressure_failures << " of " << steps
          << " steps (largest relative residual " << pressure_residual
          << "; /fluid/pressure_max_iterations, /fluid/pressure_tolerance)";
    if (viscosity_failures > 0)
        s << " the viscosity solve did not converge in " << viscosity_failures << " of " << steps
          << " steps (largest relative residual " << viscosity_residual
          << "; /fluid/viscosity_max_iterations, /fluid/viscosity_tolerance)";
    if (pass_failures > 0)
        s << " the viscous-pressure passes did not settle in " << pass_failures << " of " << steps
          << " steps (largest change " << pass_change << "; /fluid/viscous_pressure/max_passes)";
    return s.str();
}

void FrameOpenBoundaries::add(const coupling::OpenBoundaryReport& r) {
    volumes += r.volumes;
    clips += r.clips;
    components_removed += r.components_removed;
    deferred_clips += r.deferred_clips;
    unfed_inflows += r.unfed_inflows;
    if (!r.deferred.empty())
        deferred = r.deferred;
}

nlohmann::json FrameOpenBoundaries::json(
    const coupling::BoundaryVolumes& total,
    const std::vector<coupling::InflowAttachment>& inflows) const {
    static const char* const faces[3][2] = {
        {"x_min", "x_max"}, {"y_min", "y_max"}, {"z_min", "z_max"}};
    nlohmann::json attached = nlohmann::json::array();
    for (const coupling::InflowAttachment& a : inflows)
        attached.push_back({{"face", faces[a.axis][a.side]}, {"attached_reach", a.reach}});
    const auto figures = [](const coupling::BoundaryVolumes& v) {
        return nlohmann::json{{"liquid_in", v.liquid_in},
                              {"gas_in", v.gas_in},
                              {"liquid_out", v.liquid_out},
                              {"gas_out", v.gas_out}};
    };
    return {{"frame", figures(volumes)},
            {"total", figures(total)},
            {"clips", clips},
            {"components_removed", components_removed},
            {"deferred_clips", deferred_clips},
            {"unfed_inflow_steps", unfed_inflows},
            {"inflows", attached}};
}

std::string FrameOpenBoundaries::warning(int frame) const {
    if (deferred_clips == 0)
        return "";
    return "warning: frame " + std::to_string(frame) + ": the mesh could not be cut at an " +
           "outflow face in " + std::to_string(deferred_clips) + " steps (" + deferred +
           "); what reaches past it stays until a later cut";
}

nlohmann::json fluid_frame_stats(int frame, double time, long long steps,
                                 const coupling::Simulation& sim,
                                 const coupling::SimulationStepReport& last,
                                 const nlohmann::json& seconds, const nlohmann::json& work) {
    double max_speed = 0.0;
    const fluid::MacGrid& grid = sim.fluid().grid();
    for (int axis = 0; axis < 3; ++axis) {
        const fluid::Array3<double>& u = grid.velocity(axis);
        for (int k = 0; k < u.nk(); ++k)
            for (int j = 0; j < u.nj(); ++j)
                for (int i = 0; i < u.ni(); ++i)
                    max_speed = std::max(max_speed, std::abs(u(i, j, k)));
    }
    max_speed = sim.fluid().blocks().max(max_speed);  // the whole grid's on several ranks
    nlohmann::json line = {{"frame", frame},
                           {"time", time},
                           {"dt", last.dt},
                           {"dt_limit", coupling::to_string(last.limit)},
                           {"steps", steps},
                           {"volume_targets", last.volume.targets},
                           {"kinetic_energy", sim.kinetic_energy()},
                           {"max_speed", max_speed},
                           {"pressure_iterations", last.fluid.pressure.iterations},
                           {"pressure_converged", last.fluid.pressure.converged},
                           {"seconds", seconds}};
    line.update(surface_stats(sim.tracker().mesh()));
    line.update(work);
    return line;
}

}  // namespace meniscus::app
