// draglab/drag_db/dataset.h: drag datasets, the input of the fitter.
//
// A dataset is one table of drag measurements on a (phi, Re) grid: per point the mean canonical
// drag-only F over packing realizations with its standard error, extrapolated in resolution
// (Richardson with the measured order, or the seed's 1/d extrapolation) with a discretisation-error
// estimate, and the total 1-sigma uncertainty. Conventions (drag_db/conventions.h): F = F_d/(3 pi
// mu d eps u) drag only, Re = rho eps d u / mu with the superficial velocity eps u.
//
// Datasets are immutable once stored: the content hash (SHA-256 over the canonical JSON of the
// points) is their identity, the id is its first 12 hex digits, and SQL triggers refuse UPDATE and
// DELETE (schema version 4, docs/database.md). Storing the same points twice returns the
// existing dataset. They come from a campaign (campaign::build_dataset) or from a CSV file
// (users' own LBM or DNS data: read_dataset_csv). Storage: drag_db/src/db/dataset_store.cc.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace draglab {
class Database;

/// One (phi, Re) point. Absolute uncertainties (same units as F), 1 sigma.
struct DatasetPoint {
  double phi = 0.0;               ///< Solids fraction (exact, of the packings).
  double re_target = 0.0;         ///< Requested Re (0 = Stokes flow).
  double re = 0.0;                ///< Mean achieved Re = U d / nu (superficial), 0 for Stokes runs.
  double F = 0.0;                 ///< Canonical drag-only F, resolution-extrapolated mean.
  double F_standard_error = 0.0;  ///< Over realizations (0 if only one).
  double F_discretisation_error = 0.0;  ///< Resolution-extrapolation (or engine) estimate.
  double F_uncertainty = 0.0;           ///< sqrt(standard_error^2 + discretisation_error^2).
  int realizations = 0;                 ///< Converged realizations that entered the mean.
  std::vector<double> resolutions;      ///< Resolutions d (lattice units per diameter) used.
  std::vector<double> F_at_resolution;  ///< Mean F at each resolution (same order).
  double order = 0.0;                   ///< Convergence order used (0: none / not measured).
  std::string extrapolation;            ///< "richardson", "inverse_d" or "finest".
  double wall_s = 0.0;                  ///< Total LBM run time of the point's units.
  /// A size class of a polydisperse packing: y = d_i/<d> (Sauter mean), F its own drag F_i
  /// normalised with d_i, Re on <d>; 0 for a mixture or monodisperse point. Fits of polydisperse
  /// forms take it as their extra input.
  double y = 0.0;
};

struct Dataset {
  std::string id;                ///< First 12 hex digits of `hash`.
  std::string hash;              ///< SHA-256 over the canonical JSON of the points (dataset_hash).
  std::int64_t campaign_id = 0;  ///< 0 for imported data.
  std::string name;              ///< Campaign name or the imported file's stem.
  std::string method;            ///< How it was built: JSON text (extrapolation, options).
  std::string created_at;        ///< ISO 8601 UTC.
  std::string code_version;      ///< draglab version that built it.
  std::vector<DatasetPoint> points;
};

/// SHA-256 of `data` as 64 lower-case hex digits: the hash of law contents, datasets and
/// packings.
std::string sha256_hex(const std::string& data);

/// SHA-256 (hex) of the canonical JSON of the points (values as %.17g) without their wall_s:
/// the measurements, not the machine's speed, identify a dataset.
std::string dataset_hash(const std::vector<DatasetPoint>& points);

/// Stores `dataset` (computing hash and id; created_at and code_version if empty) in one
/// transaction; if a dataset with the same hash exists, returns that one unchanged.
Dataset store_dataset(Database& db, Dataset dataset);
/// Loads by id or unique hash prefix (at least 4 hex digits); throws Error(kNotFound).
Dataset load_dataset(const Database& db, const std::string& id_or_prefix);
/// All datasets, newest first, without their points.
std::vector<Dataset> list_datasets(const Database& db);

/// A (phi, Re_target) box, bounds included (to 1e-9: a packing's phi is the grid's to round-off).
struct DatasetBox {
  double phi_lo = 0.0, phi_hi = 0.0, re_lo = 0.0, re_hi = 0.0;
  bool contains(const DatasetPoint& p) const {
    constexpr double kSlack = 1e-9;
    return p.phi >= phi_lo - kSlack && p.phi <= phi_hi + kSlack && p.re_target >= re_lo - kSlack &&
           p.re_target <= re_hi + kSlack;
  }
};

/// `base` extended beyond `box` (the grid base was measured on) by the points of `extension`
/// that lie outside it: a campaign measured over a small box, completed where it cannot measure in
/// its time by data measured elsewhere (the quick preset and the shipped standard dataset). Inside
/// the box base's points alone count. The result keeps base's name and campaign, its points
/// sorted by (phi, Re_target); its method is base's with "extended_with": base's id, the
/// extension's id, hash, name, `extension_source` (its file), the box and the points taken.
/// Throws Error(kInvalidArgument) if no point of `extension` lies outside the box, if a point of
/// base lies outside it, or if either holds size-class (y) points.
Dataset extend_dataset(const Dataset& base, const DatasetBox& box, const Dataset& extension,
                       const std::string& extension_source);

/// CSV with a header line; columns phi,re,F,F_uncertainty are required (re_target defaults to
/// re, the other fields to 0/empty; y, if given, must be > 0 in every row), '#' lines are comments.
/// Throws Error(kInvalidArgument) naming the line and column for malformed input (non-numeric, phi
/// outside (0, 0.74], Re < 0, F <= 0, uncertainty <= 0).
Dataset read_dataset_csv(const std::string& path);
/// The CSV text of every field of the points (resolutions joined with ';'), after a header of
/// '#' lines: id, hash and conventions, then each `provenance` line (multi-line entries split).
std::string dataset_csv_text(const Dataset& dataset,
                             const std::vector<std::string>& provenance = {});
/// dataset_csv_text written to a regular file `path` through a temporary name and a rename (a
/// reader never sees half a file; not for devices or pipes: print dataset_csv_text instead).
void write_dataset_csv(const Dataset& dataset, const std::string& path,
                       const std::vector<std::string>& provenance = {});

}  // namespace draglab
