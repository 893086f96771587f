// plan.cc: plan_campaign -- units, memory and predicted run time of a spec before any work.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <queue>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "campaign_internal.h"
#include "draglab/arrays/packing.h"
#include "draglab/arrays/voxelization.h"
#include "draglab/campaign/campaign.h"
#include "draglab/core/text.h"
#include "draglab/error.h"
#include "draglab/lbm/lbm.h"
#include "draglab/lbm/resolution.h"

namespace draglab {
namespace campaign {
namespace {

constexpr double kMemoryShare = 0.8;

using core::format_fixed;

std::string duration(double seconds) {
  if (seconds < 120.0) return format_fixed("%.0f s", seconds);
  if (seconds < 7200.0) return format_fixed("%.1f min", seconds / 60.0);
  if (seconds < 2.0 * 86400.0) return format_fixed("%.1f h", seconds / 3600.0);
  if (seconds < 730.0 * 86400.0) return format_fixed("%.1f days", seconds / 86400.0);
  return format_fixed("%.1f years", seconds / (365.25 * 86400.0));
}

/// Seconds per fluid-node update of one worker: a fixed number of steps of the full
/// (non-linear) kernel with interpolated bounce-back in the spec's precision, on a box beyond the
/// last-level cache (where campaign units run: memory-bound), run by `workers` copies at once on
/// one thread each, as the runner's workers share the memory bandwidth. TRT on a 16-sphere
/// phi = 0.2 packing at d = 24 (84^3 nodes); the regularized operator, whose wall correction
/// costs per boundary link, on a dense one (16 spheres, phi = 0.5, d = 32), where campaigns run
/// it most.
double measure_node_update_seconds(lbm::Precision precision, lbm::Collision collision,
                                   int workers) {
  const bool regularized = collision == lbm::Collision::kRegularized;
  arrays::RandomPackingOptions po;
  po.phi = regularized ? 0.5 : 0.2;
  po.n = 16;
  po.seed = 1;
  const arrays::Packing packing = arrays::generate_random_packing(po);
  lbm::RunOptions ro;
  ro.re = regularized ? 30.0 : 10.0;
  ro.collision = collision;
  ro.max_steps = 120;
  ro.threads = 1;
  ro.precision = precision;
  ro.throw_on_failure = false;  // the step limit is the point: it stops before convergence
  const double d = regularized ? 32.0 : 24.0;
  std::vector<double> mflups(static_cast<std::size_t>(workers), 0.0);
  std::vector<std::thread> copies;
  for (int w = 0; w < workers; ++w) {
    copies.emplace_back([&, w] { mflups[w] = lbm::run(packing, d, ro).mflups; });
  }
  for (std::thread& t : copies) t.join();
  double seconds = 0.0;
  for (double m : mflups) {
    if (!(m > 0.0)) {
      throw Error(ErrorCode::kInternal, "campaign plan: the timing run measured no speed");
    }
    seconds += 1e-6 / m / workers;
  }
  return seconds;
}

/// The generator's message on one line, its first attempts only.
std::string one_line(const std::string& message) {
  constexpr std::size_t kLength = 200;
  std::string line;
  for (char c : message) {
    if (c == '\n') c = ' ';
    if (c == ' ' && !line.empty() && line.back() == ' ') continue;
    line += c;
  }
  return line.size() > kLength ? line.substr(0, kLength) + " ..." : line;
}

/// Generates every packing the units will use (one per phi and realization; cheap beside any
/// unit): a packing the generator cannot make fails all its units at run time, so the plan says
/// so before any work.
void check_packings(const CampaignSpec& spec, CampaignPlan* plan) {
  // Beyond this many spheres in all the packings the check could take longer than the plan is
  // meant to (large boxes, many realizations): it is skipped, and the report says so.
  constexpr double kMaxCheckedSpheres = 20000.0;
  double spheres = 0.0;
  for (double phi : spec.phi) {
    spheres += static_cast<double>(internal::packing_options(spec, phi, 1).n) * spec.realizations;
  }
  if (spheres > kMaxCheckedSpheres) return;
  plan->packings_checked = true;
  for (int i = 0; i < static_cast<int>(spec.phi.size()); ++i) {
    std::vector<int> failed;
    std::string first_reason;
    for (int r = 0; r < spec.realizations; ++r) {
      const arrays::RandomPackingOptions po =
          internal::packing_options(spec, spec.phi[i], internal::packing_seed(spec.seed, i, r));
      try {
        arrays::generate_random_packing(po);
      } catch (const Error& e) {
        failed.push_back(r);
        if (first_reason.empty()) first_reason = e.what();
      }
    }
    if (failed.empty()) continue;
    std::int64_t units = 0;
    for (double re : spec.re) {
      units +=
          static_cast<std::int64_t>(failed.size() * spec.point_resolutions(spec.phi[i], re).size());
    }
    plan->unpackable_units += units;
    std::string which;
    for (int r : failed) which += (which.empty() ? "" : ", ") + std::to_string(r);
    plan->packing_failures.push_back("phi = " + core::format_number(spec.phi[i]) + ", realization" +
                                     (failed.size() > 1 ? "s " : " ") + which + ": " +
                                     one_line(first_reason));
  }
}

}  // namespace

CampaignPlan plan_campaign(const CampaignSpec& spec, int jobs, double node_update_seconds) {
  std::string error;
  if (!spec.IsValid(&error)) throw Error(ErrorCode::kInvalidArgument, error);
  if (jobs < 1 || jobs > 1024) {
    throw Error(ErrorCode::kInvalidArgument,
                "campaign plan: jobs = " + std::to_string(jobs) + " is outside [1, 1024]");
  }
  if (!(node_update_seconds >= 0.0) || !std::isfinite(node_update_seconds)) {
    throw Error(ErrorCode::kInvalidArgument,
                "campaign plan: node_update_seconds must be >= 0 (0 = measure)");
  }
  const lbm::Precision precision = lbm::precision_from_string(spec.precision);
  CampaignPlan plan;
  plan.jobs = jobs;
  // As many timing copies as workers will run at once on this node.
  const int concurrent = std::max(
      1, std::min(jobs, static_cast<int>(std::max(1u, std::thread::hardware_concurrency()))));
  plan.node_update_seconds =
      node_update_seconds > 0.0
          ? node_update_seconds
          : measure_node_update_seconds(precision, lbm::Collision::kTrt, concurrent);
  plan.rr_node_update_seconds =
      node_update_seconds > 0.0
          ? node_update_seconds
          : measure_node_update_seconds(precision, lbm::Collision::kRegularized, concurrent);
  const lbm::Collision collision = lbm::collision_from_string(spec.collision);
  std::vector<double> unit_seconds;
  for (double phi : spec.phi) {
    const int n = internal::packing_options(spec, phi, 1).n;
    const double edge = std::cbrt(n * M_PI / (6.0 * phi));  // box edge in diameters
    for (double re : spec.re) {
      for (double d : spec.point_resolutions(phi, re)) {
        PlannedPoint p;
        const lbm::Collision runs = lbm::choose_collision(phi, re, d, collision).collision;
        p.collision = lbm::to_string(runs);
        p.phi = phi;
        p.re = re;
        p.resolution = d;
        p.units = spec.realizations;
        const double nodes = std::pow(edge * d, 3);
        p.fluid_nodes = nodes * (1.0 - phi);
        p.steps = lbm::predicted_steps(phi, re, d, collision);
        p.unsteady = lbm::expects_unsteady_flow(phi, re);
        p.unit_seconds = p.fluid_nodes * p.steps *
                         (runs == lbm::Collision::kRegularized ? plan.rr_node_update_seconds
                                                               : plan.node_update_seconds);
        p.memory_bytes = lbm::estimated_run_bytes(nodes, precision);
        const lbm::ResolutionNeed need = lbm::resolution_needed(phi, re, collision);
        p.d_needed = need.d;
        p.resolution_detail = need.Summary();
        const lbm::VelocityPlan velocity =
            re > 0.0
                ? lbm::plan_velocity(phi, re, d, collision, lbm::kDefaultMachTarget, 0.0, false)
                : lbm::VelocityPlan();
        if (re > 0.0 && !velocity.within_limit()) {
          p.resolution_verdict = "refused";
          plan.refused_units += p.units;
        } else if (re > 0.0 && d < need.stability) {
          p.resolution_verdict = "may diverge";
          plan.unstable_units += p.units;
        } else if (d < std::max(need.gaps, need.boundary_layer)) {
          p.resolution_verdict = "under-resolved";
          plan.under_resolved_units += p.units;
        } else {
          p.resolution_verdict = "ok";
        }
        plan.units += p.units;
        plan.core_seconds += p.units * p.unit_seconds;
        plan.largest_unit_memory_bytes = std::max(plan.largest_unit_memory_bytes, p.memory_bytes);
        for (int r = 0; r < p.units; ++r) unit_seconds.push_back(p.unit_seconds);
        plan.points.push_back(p);
      }
    }
  }
  check_packings(spec, &plan);
  // Longest first onto the least loaded worker, as the runner hands out its units.
  std::sort(unit_seconds.begin(), unit_seconds.end(), std::greater<double>());
  std::priority_queue<double, std::vector<double>, std::greater<double>> load;
  for (int w = 0; w < jobs; ++w) load.push(0.0);
  for (double t : unit_seconds) {
    const double least = load.top();
    load.pop();
    load.push(least + t);
  }
  while (!load.empty()) {
    plan.wall_seconds = std::max(plan.wall_seconds, load.top());
    load.pop();
  }
  plan.machine_memory_bytes = lbm::physical_memory_bytes();
  plan.fits_in_memory =
      plan.machine_memory_bytes <= 0.0 ||
      plan.largest_unit_memory_bytes * jobs <= kMemoryShare * plan.machine_memory_bytes;
  return plan;
}

std::string CampaignPlan::BriefReport() const {
  return std::to_string(units) + " units, predicted " + duration(wall_seconds) + " on " +
         std::to_string(jobs) + " worker" + (jobs == 1 ? "" : "s") + " (" +
         format_fixed("%.3g", core_seconds) + " core-seconds), largest unit " +
         format_fixed("%.2g", largest_unit_memory_bytes / 1073741824.0) + " GiB" +
         (fits_in_memory ? "" : ": DOES NOT FIT in memory") +
         (refused_units > 0 ? "; " + std::to_string(refused_units) +
                                  " units WILL BE REFUSED (cell Reynolds number: raise d)"
                            : std::string()) +
         (unstable_units > 0 ? "; " + std::to_string(unstable_units) +
                                   " units may diverge (beyond the cell Reynolds number their "
                                   "operator has held: raise d)"
                             : std::string()) +
         (under_resolved_units > 0
              ? "; " + std::to_string(under_resolved_units) + " units under-resolved"
              : std::string()) +
         (unpackable_units > 0
              ? "; " + std::to_string(unpackable_units) +
                    " units WILL FAIL: their packings cannot be generated (more spheres per box, "
                    "or another seed)"
              : std::string());
}

std::string CampaignPlan::FullReport() const {
  std::ostringstream out;
  out << "phi     Re      d      units  collision  flow      fluid nodes  steps     unit time   "
         "memory/unit  d needed  resolution\n";
  for (const PlannedPoint& p : points) {
    char line[240];
    std::snprintf(line, sizeof line,
                  "%-7.3g %-7.4g %-6.4g %-6d %-10s %-9s %-12.3g %-9.3g %-11s %-12s %-9.3g %s\n",
                  p.phi, p.re, p.resolution, p.units, p.collision.c_str(),
                  p.re == 0.0 ? "Stokes" : (p.unsteady ? "unsteady" : "steady"), p.fluid_nodes,
                  p.steps, duration(p.unit_seconds).c_str(),
                  format_fixed("%.2g GiB", p.memory_bytes / 1073741824.0).c_str(), p.d_needed,
                  p.resolution_verdict.c_str());
    out << line;
  }
  out << "d needed: the largest of the bounds from the pores' hydraulic diameter, the boundary "
         "layer and the cell Reynolds number the collision holds (lbm/resolution.h); collision "
         "auto runs trt where kappa Re/d is within what trt holds, rr with TRT's wall beyond; flow "
         "unsteady: expected to be time-averaged over "
      << format_fixed("%g", lbm::RunOptions().average_time)
      << " d/U after its start-up (counted in steps)\n";
  out << "time per fluid-node update (one worker of " << jobs
      << ", measured): " << format_fixed("%.3g", node_update_seconds * 1e9) << " ns (trt), "
      << format_fixed("%.3g", rr_node_update_seconds * 1e9) << " ns (rr)\n";
  for (const std::string& f : packing_failures) out << "packing fails: " << f << "\n";
  if (!packings_checked) {
    out << "packings not generated (too many spheres for a quick check): a packing that cannot "
           "be made fails its units at run time\n";
  }
  out << BriefReport() << "\n";
  return out.str();
}

}  // namespace campaign
}  // namespace draglab
