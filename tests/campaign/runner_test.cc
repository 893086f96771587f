// The campaign runner end to end on tiny Stokes campaigns (8 spheres, d = 10, ~0.3 s a unit):
// SIGKILL mid-run then --resume (nothing lost, nothing duplicated, finished units untouched),
// deterministic packings, a diverging unit recorded as failed with its diagnosis, the
// one-process lock, bad specs that exit 2 and write nothing, and a unit killed mid-run that goes
// on from its checkpoint.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>

#include <chrono>
#include <cstdlib>
#include <map>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "campaign_test_util.h"
#include "draglab/campaign/campaign.h"
#include "draglab/drag_db/database.h"
#include "draglab/drag_db/dataset.h"
#include "draglab/error.h"
#include "runner_internal.h"

namespace draglab {
namespace campaign {
namespace {

using campaign_test::RawDb;
using campaign_test::run_cli;
using campaign_test::TempDir;
using campaign_test::write_file;

const char* kTinySpec = R"(# 8 Stokes units of ~0.3 s (tests/campaign/runner_test.cc)
[campaign]
name = "tiny"
[grid]
phi = [0.1, 0.2, 0.3, 0.4]
re = [0]
realizations = 2
seed = 11
[packing]
spheres = 8
[lbm]
resolutions = [10]
[dataset]
extrapolation = "finest"
)";

/// Starts `draglab --db DB campaign run SPEC --jobs 1 [extra]` as a child process.
pid_t spawn_campaign(const std::string& db, const std::string& spec) {
  const pid_t pid = fork();
  if (pid == 0) {
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, 1);
    dup2(null, 2);
    execl(DRAGLAB_CLI, DRAGLAB_CLI, "--db", db.c_str(), "campaign", "run", spec.c_str(), "--jobs",
          "1", static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

/// Units in `status`, or -1 while the database or its tables do not exist yet.
long long count_status(const std::string& db, const std::string& status) {
  if (!campaign_test::exists(db)) return -1;
  try {
    RawDb raw(db);
    return raw.integer("SELECT count(*) FROM campaign_units WHERE status = '" + status + "'");
  } catch (const std::exception&) {
    return -1;
  }
}

TEST(CampaignRunner, SigkillThenResumeLosesNothingAndDuplicatesNothing) {
  TempDir dir;
  const std::string db = dir.file("kill.db"), spec = dir.file("tiny.toml");
  write_file(spec, kTinySpec);
  const pid_t child = spawn_campaign(db, spec);
  ASSERT_GT(child, 0);
  // Kill as soon as two units are committed (the others take ~2 s more).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (count_status(db, "done") < 2 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(kill(child, SIGKILL), 0);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the campaign finished before it could be killed";

  std::vector<std::string> before;
  long long running_at_kill = 0;
  {
    RawDb raw(db);
    EXPECT_EQ(raw.integer("SELECT count(*) FROM campaign_units"), 8);
    const long long done = raw.integer("SELECT count(*) FROM campaign_units WHERE status='done'");
    running_at_kill = raw.integer("SELECT count(*) FROM campaign_units WHERE status='running'");
    EXPECT_GE(done, 2);
    EXPECT_LE(running_at_kill, 1);  // --jobs 1: at most the unit in flight
    ASSERT_LT(done, 8) << "nothing left to resume: make the units slower";
    before = raw.rows(
        "SELECT id, phi_index, realization, F, finished_at, packing_hash, steps FROM "
        "campaign_units WHERE status = 'done' ORDER BY id");
  }

  // Without --resume the existing campaign is refused (bad input), and nothing changes.
  std::string out, err;
  EXPECT_EQ(run_cli({"--db", db, "campaign", "run", spec, "--jobs", "1"}, dir.path(), &out, &err),
            2);
  EXPECT_NE(err.find("use --resume"), std::string::npos) << err;

  ASSERT_EQ(run_cli({"--db", db, "--json", "campaign", "run", spec, "--resume", "--jobs", "1"},
                    dir.path(), &out, &err),
            0)
      << err;
  const auto j = nlohmann::json::parse(out);
  EXPECT_EQ(j["units_total"], 8);
  EXPECT_EQ(j["units_done"], 8);
  EXPECT_EQ(j["units_failed"], 0);
  EXPECT_TRUE(j.contains("dataset_id"));
  EXPECT_EQ(j["dataset_points"], 4);

  RawDb raw(db);
  EXPECT_EQ(raw.integer("SELECT count(*) FROM campaign_units"), 8);
  EXPECT_EQ(raw.integer("SELECT count(*) FROM campaign_units WHERE status = 'done'"), 8);
  EXPECT_EQ(raw.integer("SELECT count(*) FROM (SELECT DISTINCT phi_index, re_index, realization, "
                        "resolution_index FROM campaign_units)"),
            8);
  // Units finished before the kill are untouched (same F, time, packing); the one in flight ran
  // once more (attempts 2); every other unit ran exactly once.
  const std::vector<std::string> after = raw.rows(
      "SELECT id, phi_index, realization, F, finished_at, packing_hash, steps FROM campaign_units "
      "ORDER BY id");
  std::map<std::string, std::string> by_id;
  for (const auto& row : after) by_id[row.substr(0, row.find('|'))] = row;
  for (const auto& row : before) EXPECT_EQ(by_id[row.substr(0, row.find('|'))], row);
  EXPECT_EQ(raw.integer("SELECT sum(attempts) FROM campaign_units"), 8 + running_at_kill);
  EXPECT_EQ(raw.integer("SELECT count(*) FROM campaigns"), 1);

  // Status: the documented JSON fields.
  ASSERT_EQ(run_cli({"--db", db, "--json", "campaign", "status", "tiny"}, dir.path(), &out, &err),
            0);
  const auto s = nlohmann::json::parse(out);
  EXPECT_EQ(s["units_total"], 8);
  EXPECT_EQ(s["units_done"], 8);
  EXPECT_EQ(s["units_failed"], 0);

  // The dataset survives CSV export and import into another database unchanged (same points,
  // so the same content hash and id), and `dataset show --json` lists its points.
  const std::string dataset_id = j["dataset_id"].get<std::string>();
  ASSERT_EQ(run_cli({"--db", db, "dataset", "export", dataset_id, "--out", dir.file("d.csv")},
                    dir.path(), &out, &err),
            0)
      << err;
  ASSERT_EQ(
      run_cli({"--db", dir.file("import.db"), "--json", "dataset", "import", dir.file("d.csv")},
              dir.path(), &out, &err),
      0)
      << err;
  EXPECT_EQ(nlohmann::json::parse(out)["id"], dataset_id);
  ASSERT_EQ(run_cli({"--db", db, "--json", "dataset", "show", dataset_id}, dir.path(), &out, &err),
            0);
  EXPECT_EQ(nlohmann::json::parse(out)["points"].size(), 4u);

  // Deterministic seeds: the same spec in a fresh database, with 2 workers instead of 1, builds
  // the same packings (bit-identical hashes) and the same drag up to the convergence tolerance
  // (the thread count changes the rounding of reductions, and so possibly the stopping step;
  // tolerance 1e-5 per characteristic time bounds the difference well below 1e-4).
  const std::string db2 = dir.file("again.db");
  ASSERT_EQ(run_cli({"--db", db2, "campaign", "run", spec, "--jobs", "2"}, dir.path(), &out, &err),
            0)
      << err;
  RawDb raw2(db2);
  const std::string key =
      "SELECT phi_index || '/' || realization, packing_hash, F FROM campaign_units ORDER BY "
      "phi_index, realization";
  const auto a = raw.rows(key), b = raw2.rows(key);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto split = [](const std::string& r) {
      const std::size_t p = r.rfind('|');
      return std::make_pair(r.substr(0, p), std::stod(r.substr(p + 1)));
    };
    EXPECT_EQ(split(a[i]).first, split(b[i]).first);
    EXPECT_NEAR(split(a[i]).second, split(b[i]).second, 1e-4 * split(a[i]).second);
  }
}

// A unit killed mid-run goes on from its checkpoint. Set-up: one unit at Re 10 (8 spheres, phi
// 0.3, d 12, a few seconds) with a checkpoint at every convergence check, killed once its
// first checkpoint is on disk. Reference: the same spec run without a kill in another database,
// on the same single thread: the resumed unit must give its F bit for bit, say where it went on
// from, and leave no checkpoint behind.
const char* kCheckpointSpec = R"(# 1 unit at Re 10 (tests/campaign/runner_test.cc)
[campaign]
name = "resumable"
[grid]
phi = [0.3]
re = [10]
realizations = 1
seed = 5
[packing]
spheres = 8
[lbm]
resolutions = [12]
[dataset]
extrapolation = "finest"
)";

/// Starts `draglab --db DB ARGS...` as a child process (its output discarded); -1 if fork fails.
pid_t spawn_draglab(const std::string& db, const std::vector<std::string>& args) {
  const pid_t child = fork();
  if (child == 0) {
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, 1);
    dup2(null, 2);
    std::vector<const char*> argv = {DRAGLAB_CLI, "--db", db.c_str()};
    for (const std::string& a : args) argv.push_back(a.c_str());
    argv.push_back(nullptr);
    execv(DRAGLAB_CLI, const_cast<char* const*>(argv.data()));
    _exit(127);
  }
  return child;
}

/// Resumes the one-unit campaign `run_args` in `db`, runs it afresh in another database, and
/// gives both units' records.
void resume_and_run_afresh(const TempDir& dir, const std::string& db,
                           const std::vector<std::string>& run_args, nlohmann::json* resumed,
                           nlohmann::json* fresh) {
  std::string out, err;
  std::vector<std::string> resume = {"--db", db};
  resume.insert(resume.end(), run_args.begin(), run_args.end());
  resume.push_back("--resume");
  ASSERT_EQ(run_cli(resume, dir.path(), &out, &err), 0) << err;
  const std::string reference_db = dir.file("reference.db");
  std::vector<std::string> reference = {"--db", reference_db};
  reference.insert(reference.end(), run_args.begin(), run_args.end());
  ASSERT_EQ(run_cli(reference, dir.path(), &out, &err), 0) << err;
  RawDb resumed_raw(db), reference_raw(reference_db);
  *resumed = nlohmann::json::parse(
      resumed_raw.rows("SELECT result_json FROM campaign_units WHERE status = 'done'").at(0));
  *fresh = nlohmann::json::parse(
      reference_raw.rows("SELECT result_json FROM campaign_units WHERE status = 'done'").at(0));
}

TEST(CampaignRunner, UnitKilledMidRunGoesOnFromItsCheckpoint) {
  TempDir dir;
  const std::string db = dir.file("ck.db"), spec = dir.file("resumable.toml");
  write_file(spec, kCheckpointSpec);
  const std::vector<std::string> run_args = {
      "campaign", "run", spec, "--jobs", "1", "--threads-per-unit", "1", "--checkpoint-interval",
      "0"};
  const pid_t child = spawn_draglab(db, run_args);
  ASSERT_GE(child, 0);
  const std::string checkpoint = db + ".campaign-1-unit-1.checkpoint";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!campaign_test::exists(checkpoint) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(kill(child, SIGKILL), 0);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the unit finished before it could be killed";
  ASSERT_TRUE(campaign_test::exists(checkpoint));

  // `campaign status` reads where the killed unit stood from its checkpoint: the step the resumed
  // run then goes on from.
  std::string status_out, status_err;
  ASSERT_EQ(run_cli({"--db", db, "--json", "campaign", "status", "resumable"}, dir.path(),
                    &status_out, &status_err),
            0)
      << status_err;
  const auto in_progress = nlohmann::json::parse(status_out).at("in_progress");
  ASSERT_EQ(in_progress.size(), 1u) << status_out;
  EXPECT_EQ(in_progress[0].at("status"), "running") << "the killed process left it so";
  const long long step_at_kill = in_progress[0].at("step").get<long long>();
  EXPECT_GT(step_at_kill, 0);
  ASSERT_EQ(run_cli({"--db", db, "campaign", "status", "resumable"}, dir.path(), &status_out,
                    &status_err),
            0);
  EXPECT_NE(status_out.find("step " + std::to_string(step_at_kill)), std::string::npos)
      << status_out;

  nlohmann::json resumed, fresh;
  resume_and_run_afresh(dir, db, run_args, &resumed, &fresh);
  EXPECT_FALSE(campaign_test::exists(checkpoint)) << "a finished unit removes its checkpoint";
  EXPECT_EQ(resumed["resumed_from_step"].get<long long>(), step_at_kill) << resumed.dump();
  EXPECT_EQ(fresh["resumed_from_step"].get<long long>(), 0);
  EXPECT_EQ(resumed["F"].get<double>(), fresh["F"].get<double>());  // the same bits
  EXPECT_EQ(resumed["steps"], fresh["steps"]);
  // The unit's cost counts the killed part too, up to its checkpoint.
  const double earlier = resumed["earlier_parts_wall_s"].get<double>();
  EXPECT_GT(earlier, 0.0) << resumed.dump();
  EXPECT_EQ(fresh["earlier_parts_wall_s"].get<double>(), 0.0);
  EXPECT_GE(
      std::stod(RawDb(db).rows("SELECT wall_s FROM campaign_units WHERE status = 'done'").at(0)),
      resumed["lbm_wall_s"].get<double>() + earlier);
}

// A resumed unit reports at once the progress its checkpoint holds; the ETA extrapolates the
// rate of what this session did, not of what it brought back (which would read seconds).
TEST(CampaignProgress, EtaAfterAResumeExtrapolatesOnlyThisSessionsWork) {
  // Half the work done, 40 % of it restored: 10 % in 60 s, so 50 % more takes 300 s.
  const std::string resumed = runner::progress_line("c", 0, 2, 0, 0.5, 0.4, 60.0, "");
  EXPECT_NE(resumed.find("eta 5m00s"), std::string::npos) << resumed;
  const std::string fresh = runner::progress_line("c", 0, 2, 0, 0.5, 0.0, 60.0, "");
  EXPECT_NE(fresh.find("eta 1m00s"), std::string::npos) << fresh;
  // Nothing done this session yet: no rate, no ETA.
  const std::string none = runner::progress_line("c", 0, 2, 0, 0.4, 0.4, 5.0, "");
  EXPECT_NE(none.find("eta ?"), std::string::npos) << none;
}

const char* kStopSpec = R"(# 1 unit at Re 10 of about 4 s (tests/campaign/runner_test.cc)
[campaign]
name = "stoppable"
[grid]
phi = [0.3]
re = [10]
realizations = 1
seed = 5
[packing]
spheres = 8
[lbm]
resolutions = [16]
[dataset]
extrapolation = "finest"
)";

// SIGTERM (a batch system's stop, the end of a session) stops `campaign run` at the unit's next
// check with its checkpoint saved (no periodic save here): exit 1 naming the resume command, the
// unit back in the queue (not failed), and the resumed campaign gives the bits of one that never
// stopped. tests/lbm/checkpoint_test.cc checks the engine's side (the save at the stop).
TEST(CampaignRunner, SigtermPutsTheUnitBackInTheQueueAndResumeGivesItsBits) {
  TempDir dir;
  const std::string db = dir.file("stop.db"), spec = dir.file("stoppable.toml");
  write_file(spec, kStopSpec);
  const std::vector<std::string> run_args = {
      "campaign", "run", spec, "--jobs", "1", "--threads-per-unit", "1", "--checkpoint-interval",
      "1000000"};
  const pid_t child = spawn_draglab(db, run_args);
  ASSERT_GE(child, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (count_status(db, "running") < 1 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // into the unit's stepping
  ASSERT_EQ(kill(child, SIGTERM), 0);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "SIGTERM ended the process instead of stopping the run";
  EXPECT_EQ(WEXITSTATUS(status), 1);
  EXPECT_EQ(count_status(db, "pending"), 1);
  EXPECT_EQ(count_status(db, "failed"), 0);

  nlohmann::json resumed, fresh;
  resume_and_run_afresh(dir, db, run_args, &resumed, &fresh);
  EXPECT_EQ(resumed["F"].get<double>(), fresh["F"].get<double>());  // the same bits
  EXPECT_EQ(resumed["steps"], fresh["steps"]);
}

TEST(CampaignRunner, DivergingUnitIsRecordedFailedAndTheOthersComplete) {
  TempDir dir;
  const std::string db_path = dir.file("fail.db");
  // Re = 300 at phi = 0.3 and d = 8 is far beyond the cell Reynolds number TRT holds (kappa Re /
  // d of about 190, limit 35): the engine refuses the unit before stepping, naming the d that
  // would hold, and the campaign records it as failed. The Stokes unit of the same packing
  // converges.
  CampaignSpec spec;
  spec.name = "diverge";
  spec.phi = {0.3};
  spec.re = {300, 0};
  spec.spheres = 8;
  spec.resolutions = {8};
  spec.collision = "trt";  // auto would run rr there
  spec.extrapolation = "finest";
  RunCampaignOptions options;
  options.jobs = 1;
  std::vector<std::string> lines;
  options.progress = [&lines](std::int64_t, std::int64_t, const std::string& line) {
    lines.push_back(line);
  };
  const CampaignStatus st = run_campaign(db_path, spec, options);
  EXPECT_EQ(st.units_total, 2);
  EXPECT_EQ(st.units_done, 1);
  EXPECT_EQ(st.units_failed, 1);
  EXPECT_EQ(st.units_pending + st.units_running, 0);
  bool reported = false;
  for (const auto& l : lines) {
    reported = reported || (l.find("FAILED") != std::string::npos &&
                            l.find("cell Reynolds number") != std::string::npos);
  }
  EXPECT_TRUE(reported);

  Database db(db_path);
  const auto units = list_units(db, st.id);
  ASSERT_EQ(units.size(), 2u);
  for (const auto& u : units) {
    if (u.re_target == 300) {
      EXPECT_EQ(u.status, "failed");
      EXPECT_NE(u.diagnosis.find("cell Reynolds number"), std::string::npos) << u.diagnosis;
      EXPECT_NE(u.diagnosis.find("--d 65 or more"), std::string::npos) << u.diagnosis;
      EXPECT_TRUE(std::isnan(u.F));  // never a drag value from a diverged run
    } else {
      EXPECT_EQ(u.status, "done");
      EXPECT_GT(u.F, 1.0);
      EXPECT_EQ(u.packing_hash.size(), 64u);
    }
  }
  // Same packing at both Re (seed from phi index and realization only).
  EXPECT_EQ(RawDb(db_path).integer("SELECT count(DISTINCT seed) FROM campaign_units"), 1);
  std::vector<std::string> skipped;
  const Dataset d = build_dataset(db, st.id, &skipped);
  EXPECT_EQ(d.points.size(), 1u);
  ASSERT_EQ(skipped.size(), 1u);
  EXPECT_NE(skipped[0].find("Re = 300"), std::string::npos);
  // Resuming a finished campaign runs nothing again (failed units stay failed: a diagnosis is
  // a result, not a retry).
  RunCampaignOptions again;
  again.resume = true;
  again.jobs = 1;
  const CampaignStatus st2 = run_campaign(db_path, spec, again);
  EXPECT_EQ(st2.units_done, 1);
  EXPECT_EQ(st2.units_failed, 1);
  EXPECT_EQ(RawDb(db_path).integer("SELECT sum(attempts) FROM campaign_units"), 2);
}

TEST(CampaignRunner, BidisperseUnitsRecordEachSizeClassForTheSpeciesExport) {
  // Two Stokes units over bidisperse packings (size ratio 2, equal volumes): each unit's record
  // holds the drag of both size classes (lbm::run_case), and `campaign export --species` lists
  // them, one row per unit and class, with the unit's mixture F = sum x_i F_i / y_i^2.
  TempDir dir;
  const std::string db_path = dir.file("bi.db");
  CampaignSpec spec;
  spec.name = "bi";
  spec.phi = {0.2};
  spec.re = {0};
  spec.realizations = 2;
  spec.spheres = 24;  // 3 large and 21 small: a large volume share of 0.53 (12 cannot reach 0.5)
  spec.distribution = "bi";
  spec.size_ratio = 2.0;
  spec.large_fraction = 0.5;
  spec.resolutions = {8};
  spec.extrapolation = "finest";
  RunCampaignOptions options;
  options.jobs = 1;
  const CampaignStatus st = run_campaign(db_path, spec, options);
  ASSERT_EQ(st.units_done, 2);
  Database db(db_path);
  std::size_t rows = 0;
  const std::string csv = export_species_csv(db, st.id, &rows);
  EXPECT_EQ(rows, 4u);
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line,
            "unit,phi,re_target,re,resolution,realization,y,x,spheres,F_i,F_i_standard_error,F");
  std::map<long, std::vector<std::vector<double>>> by_unit;
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::istringstream fields(line);
    for (std::string f; std::getline(fields, f, ',');) v.push_back(std::strtod(f.c_str(), nullptr));
    ASSERT_EQ(v.size(), 12u) << line;
    by_unit[static_cast<long>(v[0])].push_back(v);
  }
  ASSERT_EQ(by_unit.size(), 2u);
  for (const auto& [unit, classes] : by_unit) {
    ASSERT_EQ(classes.size(), 2u);
    EXPECT_NEAR(classes[1][6] / classes[0][6], 2.0, 1e-12);  // y, smallest first
    EXPECT_NEAR(classes[0][7] + classes[1][7], 1.0, 1e-12);  // x
    double mixture = 0.0;
    for (const auto& c : classes) mixture += c[7] * c[9] / (c[6] * c[6]);
    EXPECT_NEAR(mixture, classes[0][11], 1e-9 * mixture) << "unit " << unit;
    EXPECT_GT(classes[1][9], classes[0][9]);  // the large spheres: more drag per own diameter
  }
  // A campaign of one sphere size has no rows.
  EXPECT_EQ(export_species_csv(db, st.id + 1, &rows),
            "unit,phi,re_target,re,resolution,realization,y,x,spheres,F_i,F_i_standard_error,F\n");
  EXPECT_EQ(rows, 0u);
}

TEST(CampaignRunner, FloatUnitsRecordTheirPrecisionAndAgreeWithDouble) {
  // The same two finite-Re units in double and in float storage ([lbm] precision): each record
  // names its precision, and float moves F by far less than the 1e-3 the engine allows it
  // (docs/scaling.md measured at most 4e-6; the runs stop at a tolerance of 1e-5 per
  // characteristic time, so the two may stop a check apart: 1e-4 bounds that).
  TempDir dir;
  std::map<std::string, std::vector<double>> drag;
  for (const std::string precision : {"double", "float"}) {
    CampaignSpec spec;
    spec.name = "precision_" + precision;
    spec.phi = {0.3};
    spec.re = {10};
    spec.realizations = 2;
    spec.spheres = 8;
    spec.resolutions = {8};
    spec.collision = "trt";
    spec.precision = precision;
    spec.extrapolation = "finest";
    RunCampaignOptions options;
    options.jobs = 1;
    const std::string db_path = dir.file(precision + ".db");
    const CampaignStatus st = run_campaign(db_path, spec, options);
    ASSERT_EQ(st.units_done, 2);
    RawDb raw(db_path);
    for (int unit = 1; unit <= 2; ++unit) {
      const std::vector<std::string> rows =
          raw.rows("SELECT result_json FROM campaign_units WHERE id = " + std::to_string(unit));
      ASSERT_EQ(rows.size(), 1u);
      const nlohmann::json r = nlohmann::json::parse(rows[0]);
      EXPECT_EQ(r.at("precision").get<std::string>(), precision);
      drag[precision].push_back(r.at("F").get<double>());
    }
  }
  for (std::size_t u = 0; u < 2; ++u) {
    EXPECT_NEAR(drag["float"][u], drag["double"][u], 1e-4 * drag["double"][u]) << "unit " << u;
  }
}

TEST(CampaignRunner, TheResolutionRuleRunsEachPointAtItsOwnResolutions) {
  // resolutions = "rule" within [6, 10]: phi 0.3 in Stokes flow needs d >= 5.1 (its pores'
  // hydraulic diameter spans 8 nodes): one unit per realization at the floor, 6; phi 0.5 needs
  // 12, beyond the cap: 10 and 10 / 1.5 -> 8, extrapolated in d.
  TempDir dir;
  CampaignSpec spec;
  spec.name = "rule";
  spec.phi = {0.3, 0.5};
  spec.re = {0};
  spec.realizations = 2;
  spec.spheres = 8;
  spec.resolution_rule = true;
  spec.min_resolution = 6;
  spec.max_resolution = 10;
  spec.extrapolation = "richardson";
  std::string error;
  ASSERT_TRUE(spec.IsValid(&error)) << error;
  ASSERT_EQ(spec.unit_count(), 6);
  RunCampaignOptions options;
  options.jobs = 2;
  const std::string db_path = dir.file("rule.db");
  const CampaignStatus st = run_campaign(db_path, spec, options);
  ASSERT_EQ(st.units_done, 6);
  RawDb raw(db_path);
  EXPECT_EQ(raw.rows("SELECT DISTINCT resolution FROM campaign_units WHERE phi = 0.3"),
            (std::vector<std::string>{"6.0"}));
  EXPECT_EQ(raw.integer("SELECT count(*) FROM campaign_units WHERE phi = 0.5 AND resolution = 8 "
                        "AND resolution_index = 0"),
            2);
  EXPECT_EQ(raw.integer("SELECT count(*) FROM campaign_units WHERE phi = 0.5 AND resolution = 10 "
                        "AND resolution_index = 1"),
            2);
  Database db(db_path);
  const Dataset data = build_dataset(db, st.id);
  ASSERT_EQ(data.points.size(), 2u);
  const DatasetPoint& dilute = data.points[0];
  EXPECT_EQ(dilute.resolutions, std::vector<double>{6.0});
  EXPECT_EQ(dilute.extrapolation, "finest");
  const DatasetPoint& dense = data.points[1];
  EXPECT_EQ(dense.resolutions, (std::vector<double>{8.0, 10.0}));
  EXPECT_EQ(dense.extrapolation, "inverse_d");  // two resolutions: Richardson needs three
  // The line through the two realization means, by hand: F_inf = (10 F10 - 8 F8) / 2.
  EXPECT_NEAR(dense.F, (10.0 * dense.F_at_resolution[1] - 8.0 * dense.F_at_resolution[0]) / 2.0,
              1e-9 * dense.F);
  EXPECT_NEAR(dense.F_discretisation_error, std::fabs(dense.F - dense.F_at_resolution[1]),
              1e-9 * dense.F);
  EXPECT_NE(data.method.find("\"resolutions\":\"rule\""), std::string::npos) << data.method;
}

TEST(CampaignRunner, SecondProcessOnTheSameCampaignIsRefused) {
  TempDir dir;
  const std::string db = dir.file("lock.db"), spec = dir.file("tiny.toml");
  write_file(spec, kTinySpec);
  {
    // An existing database; --resume creates the campaign (id 1) and then needs its lock.
    std::string out, err;
    ASSERT_EQ(run_cli({"--db", db, "db", "info"}, dir.path(), &out, &err), 0) << err;
  }
  const int fd = open((db + ".campaign-1.lock").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(flock(fd, LOCK_EX | LOCK_NB), 0);
  ASSERT_EQ(write(fd, "pid 1 on testhost\n", 18), 18);
  std::string out, err;
  EXPECT_EQ(run_cli({"--db", db, "campaign", "run", spec, "--resume"}, dir.path(), &out, &err), 1);
  EXPECT_NE(err.find("is being run by another process (pid 1 on testhost)"), std::string::npos)
      << err;
  close(fd);
  // The campaign was created but no unit ran.
  RawDb raw(db);
  EXPECT_EQ(raw.integer("SELECT count(*) FROM campaign_units WHERE status != 'pending'"), 0);
}

TEST(CampaignCli, BadSpecExitsTwoAndWritesNothing) {
  TempDir dir;
  const std::string db = dir.file("bad.db");
  std::string out, err;
  ASSERT_EQ(run_cli({"--db", db, "db", "info"}, dir.path(), &out, &err), 0) << err;
  const std::string bytes = campaign_test::read_file(db);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"phi = [0.1, 0.2, 0.3, 0.4]", "phi = [0.1, 0.9]"},
      {"re = [0]", "re = [-1]"},
      {"re = [0]", "re = []"},
      {"seed = 11", "seed = 11\nspeed = 3"},
      {"spheres = 8", "spheres = 8\nbox_size = 3.0"},
  };
  const std::vector<std::string> expected = {
      "[grid] phi[1] = 0.9 is outside [0.05, 0.6]", "[grid] re[0] = -1 is outside [0, 1000]",
      "[grid] re has no values", "unknown key 'speed' in [grid]",
      "spheres and box_size contradict"};
  for (std::size_t i = 0; i < cases.size(); ++i) {
    std::string spec = kTinySpec;
    spec.replace(spec.find(cases[i].first), cases[i].first.size(), cases[i].second);
    write_file(dir.file("bad.toml"), spec);
    EXPECT_EQ(
        run_cli({"--db", db, "campaign", "run", dir.file("bad.toml")}, dir.path(), &out, &err), 2)
        << cases[i].second;
    EXPECT_NE(err.find(expected[i]), std::string::npos) << err;
  }
  EXPECT_EQ(campaign_test::read_file(db), bytes);  // not a byte changed
  EXPECT_EQ(RawDb(db).integer("SELECT count(*) FROM campaigns"), 0);
  // A database that does not exist is not created for a bad spec.
  EXPECT_EQ(run_cli({"--db", dir.file("new.db"), "campaign", "run", dir.file("bad.toml")},
                    dir.path(), &out, &err),
            2);
  EXPECT_FALSE(campaign_test::exists(dir.file("new.db")));
  // Unknown campaign and dataset: exit 2 (not found is bad input).
  EXPECT_EQ(run_cli({"--db", db, "campaign", "status", "nope"}, dir.path(), &out, &err), 2);
  EXPECT_NE(err.find("no campaign with name 'nope'"), std::string::npos) << err;
}

}  // namespace
}  // namespace campaign
}  // namespace draglab
