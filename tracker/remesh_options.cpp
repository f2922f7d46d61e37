#include "tracker/remesh_options.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace meniscus::tracker {

namespace {

void require(bool ok, const char* field, const char* rule) {
    if (!ok)
        throw std::invalid_argument(std::string(field) + " " + rule);
}

bool finite_positive(double v) {
    return std::isfinite(v) && v > 0.0;
}
bool open_unit(double v) {
    return std::isfinite(v) && v > 0.0 && v < 1.0;
}

}  // namespace

void RemeshOptions::validate() const {
    require(finite_positive(min_edge_fraction), "min_edge_fraction:",
            "must be finite and > 0");
    require(std::isfinite(max_edge_fraction) && max_edge_fraction > min_edge_fraction,
            "max_edge_fraction:", "must be finite and > min_edge_fraction");
    require(finite_positive(max_volume_change_fraction),
            "max_volume_change_fraction:", "must be finite and > 0");
    // Adaptive sizing terms: ≥ 0, and > 0 only with fitted split points.
    const auto adaptive_term = [this](double value, const char* field) {
        require(std::isfinite(value) && value >= 0.0, field, "must be finite and >= 0");
        require(value == 0.0 || split_on_fitted_surface, field,
                "> 0 needs split_on_fitted_surface (butterfly points on graded meshes add "
                "bumps that the curvature estimate then refines without end)");
    };
    adaptive_term(curvature_edge_fraction, "curvature_edge_fraction:");
    adaptive_term(thin_sheet_sag_fraction, "thin_sheet_sag_fraction:");
    require(std::isfinite(min_curvature_size_fraction) && min_curvature_size_fraction > 0.0 &&
                min_curvature_size_fraction <= 1.0,
            "min_curvature_size_fraction:", "must be in (0, 1]");
    require(max_split_passes >= 1, "max_split_passes:", "must be >= 1");
    require(max_collapse_passes >= 1, "max_collapse_passes:", "must be >= 1");
    require(max_flip_sweeps >= 1, "max_flip_sweeps:", "must be >= 1");
    require(std::isfinite(min_flip_length_decrease_fraction) &&
                min_flip_length_decrease_fraction >= 0.0 && min_flip_length_decrease_fraction < 1.0,
            "min_flip_length_decrease_fraction:", "must be in [0, 1)");
    require(collapse_position_attempts >= 1, "collapse_position_attempts:",
            "must be >= 1");
    require(std::isfinite(max_normal_change_degrees) && max_normal_change_degrees > 0.0 &&
                max_normal_change_degrees <= 180.0,
            "max_normal_change_degrees:", "must be in (0, 180]");
    require(open_unit(ridge_eigenvalue_ratio), "ridge_eigenvalue_ratio:",
            "must be in (0, 1)");
    require(open_unit(corner_eigenvalue_ratio), "corner_eigenvalue_ratio:",
            "must be in (0, 1)");
    require(std::isfinite(flip_fold_weight) && flip_fold_weight >= 0.0,
            "flip_fold_weight:", "must be finite and >= 0");
    require(smoothing_iterations >= 0, "smoothing_iterations:", "must be >= 0");
    require(split_fit_residual_fraction > 0.0 && split_fit_residual_fraction <= 1.0,
            "split_fit_residual_fraction:", "must be in (0, 1]");
    require(smoothing_unfitted_min_angle_degrees >= 0.0 &&
                smoothing_unfitted_min_angle_degrees <= 60.0,
            "smoothing_unfitted_min_angle_degrees:", "must be in [0, 60]");
    require(smoothing_fit_degree == 2 || smoothing_fit_degree == 3,
            "smoothing_fit_degree:", "must be 2 or 3");
    require(std::isfinite(smoothing_fit_max_turn) && smoothing_fit_max_turn >= 0.0,
            "smoothing_fit_max_turn:", "must be finite and >= 0");
    require(std::isfinite(smoothing_step_fraction) && smoothing_step_fraction > 0.0 &&
                smoothing_step_fraction <= 1.0,
            "smoothing_step_fraction:", "must be in (0, 1]");
}

void SeparationOptions::validate() const {
    require(std::isfinite(nudge_fraction) && nudge_fraction > 0.0 && nudge_fraction < 0.5,
            "separation/nudge_fraction:", "must be in (0, 0.5)");
    require(max_nudge_halvings >= 0, "separation/max_nudge_halvings:", "must be >= 0");
}

void TopologyOptions::validate() const {
    require(finite_positive(merge_distance_fraction), "merge_distance_fraction:",
            "must be finite and > 0");
    require(max_zipper_alignments >= 1 && max_zipper_alignments <= 4,
            "max_zipper_alignments:", "must be in [1, 4]");
    require(std::isfinite(merge_spacing_fraction) && merge_spacing_fraction >= 0.0,
            "merge_spacing_fraction:", "must be finite and >= 0");
    separation.validate();
}

void ImproveContext::validate() const {
    require(finite_positive(xi), "ImproveContext::xi", "must be finite and > 0");
    collision.validate();
    separation.validate();
}

void TopologyContext::validate() const {
    require(finite_positive(xi), "TopologyContext::xi", "must be finite and > 0");
}

RemeshLimits remesh_limits(const RemeshOptions& options, double xi) {
    RemeshLimits limits;
    limits.max_edge_length = options.max_edge_fraction * xi;
    limits.min_edge_length = options.min_edge_fraction * xi;
    limits.max_volume_change = options.max_volume_change_fraction * xi * xi * xi;
    return limits;
}

}  // namespace meniscus::tracker
