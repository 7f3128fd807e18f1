// Thruster fault detection and isolation: a hypothesis bank scored on the residual between the
// measured change of the body rate and the change predicted from the identified model and the
// thrust actually commanded (Wilson, Lages & Mah 2002: predict the motion for "no fault" and for
// each fault hypothesis; a hypothesis gathers evidence only when its signature is non-zero; the
// most likely one is confirmed when it is clearly ahead of every other). Design note with the
// equations (F1)... and the detection limit: README.md beside this file.
//
// Hypotheses: no fault, 16 x stuck-on (the thruster fires at u_max whatever is commanded, while its
// pod's latch valve is open), 16 x stuck-off (it produces nothing when commanded). A degraded
// thruster is the identifier's business (its strength k_i). A confirmed fault latches until the
// ground clears it; a latched stuck-on asks for its pod's latch valve to close.
//
// Flight code: fixed-size Eigen, no heap, no exceptions, no I/O.
#pragma once

#include <array>
#include <cstdint>

#include "gnc/check.hpp"
#include "gnc/fdi/balance_test.hpp"
#include "gnc/io.hpp"  // FaultKind
#include "gnc/model/rcs.hpp"
#include "gnc/types.hpp"

namespace rocksteady::gnc {


struct FaultDetectorParams {
  bool enabled{false};
  // Residual window: the rate change over this many ticks is compared with the prediction (F2).
  int window_ticks{5};
  // Noise model of the residual (F4): gyro white noise per sample (rad/s), external disturbance
  // torque per axis (N m), and a floor on the relative model uncertainty (the identifier's J 1
  // sigma relative to ||J_hat|| is used when larger).
  double gyro_sigma{1e-6};
  double disturbance_sigma{0.57735026918962576};
  double model_rel_floor{0.0};
  // (F22) Whether the floor also applies to the gyroscopic term of the model's error, whose bound
  // (F5: 2 ||J^-1|| ||J|| |w|^2) already carries the margin of a norm bound; false: the floor
  // applies to the commanded thrust's term only, the gyroscopic one takes the identifier's 1 sigma.
  bool model_floor_gyroscopic{true};
  // Sequential test (F6): a hypothesis is confirmed when its cumulative log-likelihood ratio
  // exceeds confirm_llr and leads the runner-up by margin_llr; a window whose no-fault chi-square
  // (3 dof) exceeds suspect_chi2 raises a suspicion. Calibrated on healthy runs (README §F.4).
  double confirm_llr{25.0};
  double margin_llr{10.0};
  double suspect_chi2{16.27};  // chi-square(3) at 0.999
  // A hypothesis is scored in a window only when its signature is observable there: its energy
  // |S~|^2 / var at least this (a jet that barely fired, or not at all, tells nothing).
  double min_signature{4.0};
  // true: a confirmed stuck-on closes its pod's latch valve (automatic isolation).
  bool auto_isolate{true};
  // (F21) The window a fault starts in is not scored: the first window whose no-fault chi-square
  // exceeds suspect_chi2 after one that did not (outside isolation tests, sweeps and jet checks).
  bool skip_onset_window{false};
  // (F45) With (F21) and (F33): the window whose early test first shows a fault ends there, its
  // samples dropped (F21 would not score them), and the next window starts on that sample, so the
  // first window scored is one the fault fills, a whole window sooner than the onset window's
  // close. Not while a suspicion, a test or a check is under way. false: the onset window runs
  // its course.
  bool onset_restart{false};
  // (F8) The lead over each alternative must also exceed what an error of the model could have
  // produced: this many 1 sigma of the signature's model uncertainty.
  double model_sigmas{3.0};
  // (F58) A stuck-off leader is also held back (a partial loss, F13) when its fitted loss lies
  // more than this many of the fit's own 1 sigma (1 / sqrt(E)) below the total-loss floor (F23):
  // a jet that produces nothing fits at or above the floor within its noise, while
  // partial_not_total's margin_llr asks sqrt(2 margin_llr) of them (4.5 at 10) before it calls the
  // loss partial. 0: off (margin_llr alone).
  double total_loss_sigmas{0.0};
  // (F59) After a confirmed fault, a further stuck-off or partial-loss confirmation, and any jet
  // check or survey, only on a model whose inertia is known to this relative 1 sigma
  // (FaultModel::j_rel_sigma; the identifier's confidence bound). A confirmation re-inflates the
  // identifier (F12), and one that absorbed the fault before it was isolated (a fault from the
  // despin's start) may not converge again: the evidence then gathered against that model is the
  // model's error, not a second fault. A stuck-on jet is confirmed as before. 0: off.
  double after_fault_max_j_rel{0.0};
  // (F25) The episode of (F8) restarts with the window in which a suspicion starts with a new
  // leader (false: only when every score is zero, which a stale stuck-off score of an idle jet
  // can put off for the rest of the flight); a stuck-on leader must also beat every jet's partial
  // loss of thrust.
  bool episode_restart{false};
  // (F9) Isolation test: when the leader stays ambiguous against a hypothesis on another pod for
  // this many windows, its pod's valve is closed for probe_windows windows (0: never).
  int probe_after_windows{1};
  int probe_windows{3};
  // (F46) With (F27): the window that an aligned isolation test starts is this many samples long
  // (0: window_ticks; otherwise in [4, 1000]). With probe_windows 1 that window is the test. The
  // pod's closure removes a stuck-on jet's whole torque, so the test needs as many samples as
  // the weakest jet's torque needs to stand out of the gyro's noise, fewer than the bank's
  // windows, which must also tell the jets apart by their signatures.
  int probe_window_ticks{0};
  // (F47) With (F46): a test flies the short window only when the window that started it
  // showed its leader with at least this LLR, scaled to the short window by the cube of the
  // lengths' ratio (a ramp's evidence, the weakest jet's, grows with the cube of its samples); a
  // test started on weaker evidence (a model still far from the truth) flies a whole window.
  // 0: every test short.
  double probe_short_min_llr{0.0};
  // (F52) An isolation test may start on a stuck-on leader whose score is past this, below
  // confirm_llr, so that the closed valve's evidence (E / 2 against every stuck-on jet behind an
  // open valve) comes a window or two sooner. Such a test's verdict names a jet only once that
  // jet's own score is past confirm_llr: a verdict on a test's windows alone (margin_llr over
  // them) is safe only on a leader the bank has already found. 0: tests only past confirm_llr.
  double probe_start_llr{0.0};
  // (F27) The pod's closure (a test of F9, or a sweep's of F17) starts a new window, so the test's
  // first window is flown closed throughout (the decision comes kEvaluationSteps updates into the
  // window that follows the one it read: without this, that window is flown partly open and a
  // test needs two windows for one closed throughout). The few samples of the window under way
  // are dropped.
  bool probe_aligned{false};
  // (F28) The gyro's share of a residual sample's variance (F5) is sigma_g^2: the window's start
  // sample enters every sample of the window alike, as an offset that the mean-centring (F6)
  // removes. false: 2 sigma_g^2 (the start sample's noise counted in every sample), which halves
  // every likelihood ratio where the gyro's noise dominates (cases 5-7).
  bool centred_gyro_noise{false};
  // (F29) A test's verdict (F15) names its stuck-on jet only when it also leads, over the test's
  // windows, every jet's partial loss of thrust (F13's fit) by margin_llr.
  bool probe_partial_rival{false};
  // (F32) The verdict is first read when the test's closed windows end, on the window that started
  // the test and the closed ones: the motion was there before the closure and gone behind it. It
  // names the tested pod's stuck-on jet as (F15) does, and only when the closed windows contradict
  // the alternative that started the test and every other one that window could not tell from the
  // leader; otherwise the valve reopens and (F15) reads the reopened window as before. A stuck-on
  // jet so decided never fires again (false: the valve always reopens for the verdict).
  bool probe_read_closed{false};
  // (F14) Stuck-on isolation inside identification: the identifier's constant fault torque d
  // (estimation README I22) scored against each stuck-on column (I23). Thruster i is confirmed
  // stuck on when, in identified_windows fitted windows in a row, d-hat is at least
  // identified_zero_chi2 from zero (3 dof), within identified_match_chi2 of thruster i's torque,
  // thruster i's torque itself at least identified_zero_chi2 from zero (with the model's
  // uncertainty of it), and every other thruster's chi-square exceeds i's by
  // identified_margin_chi2.
  bool identified_isolation{false};
  double identified_zero_chi2{100.0};
  double identified_match_chi2{16.27};  // chi-square(3) at 0.999
  double identified_margin_chi2{25.0};
  int identified_windows{2};
  // (F17) Pod sweep: when a fitted identifier window puts the fault torque identified_zero_chi2
  // from zero but (F14) matches no jet, each pod's valve is closed in turn for probe_windows
  // windows (pods ordered by their best-matching jet) and the step of the unexplained angular
  // acceleration at the closure and at the reopening names the stuck jet.
  bool identified_sweep{false};
  // (F18) Partial loss of thrust ("degraded"): the jet whose fitted partial loss (F13) explains the
  // episode best is confirmed degraded, its strength multiplied by 1 - the fitted loss, when that
  // loss is at least degraded_min_loss (smaller is the identifier's calibration of k), it is a
  // partial loss (not a stuck-off: its own a = 1 trails by margin_llr), and it leads every other
  // hypothesis by margin_llr plus model_sigmas of the model's error. 0: off.
  double degraded_min_loss{0.0};
  // (F51) The model's error that a fitted loss must exceed (degraded_min_loss + model_sigmas eps)
  // is that of the jet's signature along itself: the centre of mass's share from its covariance,
  // projected on the signature, for the jet alone and for its check's move (the larger), not
  // r_sigma over the jet's arm (a bound on the whole signature's error, which in cases 6-7,
  // r known to 0.56 m, put eps above 0.13 and so every half loss below the gate).
  // false: signature_rel_error as before.
  bool degraded_loss_projection{false};
  // (F19) Jet check: when a jet's stuck-off score or partial-loss CUSUM (F18) reaches check_llr
  // (the evidence of a jet the despin asks for only a few newtons), the flight fires that jet at
  // check_force_n for check_windows windows in the null space of the channels' torques (no torque
  // on the model: the detector's own with F42, check_move; the table's B_hat without),
  // so its own hypotheses are confirmed or exonerated within seconds. A jet is checked at most
  // once per check_interval_s, doubled after each check of it that confirmed nothing (up to four
  // times the interval). 0: off.
  double check_llr{0.0};
  double check_force_n{100.0};
  int check_windows{3};
  double check_interval_s{600.0};
  // A window flown with a jet check is scored only when its unexplained rate change is along the
  // checked jet's signature: the part normal to it (chi-square, 2 dof) within check_fit_chi2. A
  // check that shows a model error instead (a centre of mass or an inertia that absorbed an
  // earlier fault) decides nothing.
  double check_fit_chi2{13.82};  // chi-square(2) at 0.999
  // A jet is checked only when the model knows its signature to this relative 1 sigma (strength,
  // inertia, and the centre of mass against the jet's arm, as F18's eps): a model that absorbed
  // an earlier fault while the identifier was far from the truth makes a firm firing look like
  // a loss of thrust of another jet.
  double check_max_model_error{0.05};
  // (F24) A jet is checked only when the check can move its evidence by at least this much: the
  // stuck-off LLR a healthy jet's check is expected to lose (E / 2 over check_windows windows),
  // with what the check adds to the noise (the centre of mass's 1 sigma against the force of the
  // check and of the jets that compensate it). A check that cannot even undo the evidence that
  // started it only kicks the vehicle. 0: off.
  double check_min_llr{0.0};
  // (F31) No check starts for an evident fault that is not its jet: after a window whose no-fault
  // chi-square exceeded suspect_chi2, only a jet whose signature that window's unexplained motion
  // lies along (check_fit_chi2, as a check window's fit) may be checked. A check's windows are not
  // scored when they show motion that is not the checked jet's, so a check started on the
  // stuck-off evidence that a stuck-on jet's first window raised kept the bank from scoring the
  // stuck-on jet for the check's windows. false: as before.
  bool check_fit_on_suspicion{false};
  // (F34) No check starts on a window whose no-fault chi-square exceeded suspect_chi2 (a jet whose
  // evidence is real still has it on the next quiet window). false: as before.
  bool check_quiet_start{false};
  // (F35) A check window whose motion does not lie along the checked jet's signature (unfit,
  // check_fit_chi2) is scored like any window, with the model's error of every jet the check
  // fired (the sum of their torques' magnitudes, not of their net torque, which the check's null
  // space makes small): the jets fired beside the checked one are commanded firmly there, and a
  // stuck-off one among them shows. false: an unfit window is not scored (F19).
  bool check_score_unfit{false};
  // (F36) Jet survey: a jet the flight keeps commanding so lightly that its loss could not show
  // (in HOLD the controller asks mN of it: tens of N s over 10^4 s, against a 200 N jet) is
  // checked anyway. Each jet's stuck-off energy E (what a total loss of it would have put into
  // the score, F6) is summed from the last time it was verified; E reaching survey_energy
  // verifies it. A jet commanded since then but not verified for survey_interval_s is checked
  // (F19), the check's length sized so that its expected E reaches survey_energy (at least
  // check_windows, at most survey_max_windows windows). The check gates (model error, F24) hold.
  // 0: off.
  double survey_interval_s{0.0};
  // (F37) A stuck-off leader past confirm_llr that (F8) cannot tell from another jet's stuck-off
  // (twin jets, nearly parallel signatures, a model a few percent off) waits for evidence that
  // more of the same firing cannot give; a check of the blocking jet (F19: its interval and
  // gates) fires it alone, and exonerates or confirms it. false: as before.
  bool check_blocker{false};
  // (F38) A suspicion that starts with a leader whose episode sum trails its score by margin_llr
  // restarts the episode too (F25 restarts it for a new leader only). false: as before.
  bool episode_restart_stale{false};
  // (F41) A new leader, while a suspicion goes on, whose episode sum trails its score by
  // margin_llr restarts the episode too (its fault began after the window that started it).
  // false: as before.
  bool episode_restart_leader{false};
  // (F39) An isolation test after whose closed windows the leader is a stuck-on jet of another
  // pod, favoured by those windows, is not read on its reopened window: the next test may start
  // on the update its closure ends. false: as before.
  bool probe_chain{false};
  // (F40) An isolation test whose closed windows show the motion going on names the stuck-on jet
  // of another pod that explains the start window and the closed ones: ahead of every hypothesis
  // by margin_llr over them, ahead of every hypothesis of the tested pod by margin_llr on the
  // closed windows alone, and every other alternative told from it by the start window or
  // contradicted by the closed ones (as F32 reads the tested pod's jet). false: such a test is read
  // on its reopened window, and the leader's pod needs a test of its own.
  bool probe_read_elsewhere{false};
  // (F42) A jet check's firing is the minimum-norm move in the null space of the detector's own
  // channel torques, built on the identified centre of mass (check_move), the model it rates the
  // check with (F24). false: the null space of the active table's B_hat, whose centre of mass is
  // the a-priori one until a model is adopted (up to 1 m off in the study's cases 3, 4, 6 and 7,
  // a torque of 1 m x the check's net force on the body).
  bool check_model_null_space{false};
  // (F43) The survey checks only in HOLD (the GNC's FaultDetectorInput::survey_allowed): a despin
  // fires its jets firmly and its evidence checks are the detector's own, while in HOLD the jets
  // idle at milli-newtons. A despin's tick already carries the identifier's blocks and the
  // excitation. false: in every mode.
  bool survey_hold_only{false};
  // (F61) Channel balance tests (balance_test.hpp): in HOLD, each channel's two halves fired one
  // after the other and compared, with no model of the body. balance.kick_rad_s 0: off.
  BalanceTestParams balance{};
  // (F44) A survey check starts only when the rate it may put on the body stays within this, rad/s
  // (0: off): 3 sigma of the model's error against the check's firing (the centre of mass's 1 sigma
  // against its net force, each fired jet's strength 1 sigma against its torque) times J^-1 and
  // the check's length. After a confirmed fault the identifier restarts from its prior (I27 off)
  // and a survey check against that model kicks the rate out of the SPEC §7 bound in HOLD.
  double survey_max_kick_rad_s{0.0};
  // (F48) With (F44): no survey check where the gyro is too noisy for any check to show a jet's
  // loss within that bound. A check verifies a jet when a total loss would have given it
  // survey_energy (F36); over one window of n samples (the most a window can hold) the least
  // kick that does so is K = n sigma_g sqrt(12 E / (n (n^2 - 1))) (F6's ramp energy, sigma_g the
  // gyro's noise). Above survey_max_kick_rad_s a check of a failed jet kicks the rate past the
  // bound before it is confirmed, and a half-strength jet, not confirmed by one check, at every
  // survey interval. false: the survey checks whatever the gyro's noise.
  bool survey_noise_kick{false};
  // (F49) Where (F48) refuses the survey (the gyro too noisy for a check of the bank's windows
  // within the kick bound) and a survey may fly (HOLD, F43), every check, evidence or survey, is
  // flown as one window of check_long_ticks samples that starts with it, at the least force
  // whose expected stuck-off energy is check_long_energy (a dead jet gains half of it, a healthy
  // one loses half). A ramp's energy grows with the cube of its samples: at a fixed kick K,
  // E = K^2 (N^2 - 1) / (12 N sigma_g^2) for one window of N samples, against 1/W of that spread
  // over W windows. The check is flown only when a dead jet's kick and 3 sigma of the model's
  // (F44) stay within survey_max_kick_rad_s and the force within check_force_n. An early
  // suspicion (F33) off the checked jet's signature ends it (the window dropped, as F45). 0: off.
  // An evidence check (a jet whose stuck-off or partial-loss evidence reached check_llr) is sized
  // to check_long_evidence_energy and gated on the force only, as an evidence check of the bank's
  // windows is not gated on its kick (F44): it answers evidence of a fault, and a partial loss
  // needs the energy to be told from a total one (F23) and confirmed (F18).
  int check_long_ticks{0};
  double check_long_energy{80.0};
  double check_long_evidence_energy{320.0};
  // (F50) A long check's energy is capped by the centre of mass's 1 sigma: the force's own error
  // grows with it, so E(f) = s^2 f^2 g / (q + a^2 f^2) < s^2 g / a^2 = E_cap whatever the force.
  // Where E_cap is below check_long_evidence_energy (cases 6-7: E_cap 200-500 for r known to
  // 0.56 m), the evidence check flies at check_long_reach E_cap instead, when that reaches
  // check_long_energy; the evidence of successive checks adds up in the jet's sums (F18, F23).
  // 0: such a jet is not checked (F49).
  double check_long_reach{0.0};
  // (F56) After a confirmed fault (any jet latched on, off or degraded), an evidence check too is
  // flown only within the kick bound of a survey check (F44: 3 sigma of the rate the model's
  // error may put on the body over the check, survey_max_kick_rad_s; a long check's, F49, with a
  // dead jet's kick as well). The confirmation restarts the identifier from its prior (I27 off):
  // a check of the evidence that the re-inflated model builds up would be flown on that model,
  // and a despin flown beside its repeated checks misses its goals. A refused jet is due again
  // one check interval later, not counted as a check. false: evidence checks are never gated on
  // their kick.
  bool check_kick_after_fault{false};
  double survey_energy{10.0};  // a stuck-off jet's expected LLR is E / 2: check_llr 5 at 10
  int survey_max_windows{8};
  // (F57) A jet whose partial-loss CUSUM (F18) stands at or above this, and below check_llr, is
  // not verified by its energy (F36): survey_energy shows a total loss, not a partial one (a jet
  // at half strength gains a quarter of a dead jet's score). Such a jet is surveyed one
  // check_interval_s after it was last verified, at most once per survey_interval_s, with the
  // energy that takes its evidence past check_llr or back to zero (F18's drift at its design loss);
  // past check_llr its evidence checks (F19) answer it, as before. 0: the energy alone verifies.
  double survey_loss_llr{0.0};
  // (F33) Early detection: from detect_early_ticks samples into a window, each update tests the
  // window flown so far (the no-fault slope statistic with the noise of F5 on those samples)
  // against detect_early_chi2, and the first crossing raises the window's suspicion there and
  // then (the counter and the event; the window's own evaluation does not raise it again).
  // Scores, model holds and decisions still wait for the closed window, so isolation is the same.
  // A window's end is at most window_ticks + kEvaluationSteps updates after a fault starts; this
  // is a few updates after it shows. 0: off.
  int detect_early_ticks{0};
  double detect_early_chi2{35.41};  // chi-square(3) at 1 - 1e-7: several tests per window
};

// (F14) The identifier's stuck-on evidence after one of its windows (estimation README I23).
struct StuckOnEvidence {
  bool fitted{false};      // the window updated the identifier's estimate
  double chi2_zero{0.0};   // fault torque against zero
  std::array<double, kThrusters> chi2_jet{};  // fault torque against thruster i stuck on
  std::array<double, kThrusters> chi2_column{};  // thruster i's stuck-on torque against zero
};

Check validate(const FaultDetectorParams& p);

// (F19) The part of a window's unexplained rate-change slope normal to a jet's signature b, as a
// chi-square with 2 dof: |slope - (b.slope / |b|^2) b|^2 stt / var (stt the window's sum of
// squared sample offsets, var the residual's per-sample variance). 0 when b or stt is zero.
double check_normal_chi2(const Vec3& b, const Vec3& slope, double stt, double var);

// What the detector reads each tick.
struct FaultDetectorInput {
  Vec3 omega{Vec3::Zero()};  // measured body rate at this tick (gyro, bias-corrected), rad/s
  bool omega_valid{false};
  // Force commanded on each physical thruster over the previous tick (N, >= 0; index 2c "+",
  // 2c+1 "-" of channel c) and the pods' latch valves over that tick.
  Vec16 thrust{Vec16::Zero()};
  std::array<bool, kPods> valve_open{{true, true, true, true}};
  bool thrust_valid{true};
  // (F43) A jet survey check may start now (the GNC: only in HOLD when survey_hold_only).
  bool survey_allowed{true};
  // (F61) A channel balance test may start now (the GNC: in HOLD).
  bool balance_allowed{false};
};

// The identified model the predictions use (refreshed when the identifier reports).
struct FaultModel {
  Mat3 j{Mat3::Identity()};
  Vec3 r{Vec3::Zero()};
  Vec16 k{Vec16::Ones()};
  double j_rel_sigma{1.0};  // largest 1 sigma of J relative to ||J|| (the identifier's)
  // m^2, covariance of r: its largest 1 sigma r_sigma gives a torque error of r_sigma x the net
  // force (F5); the isolation test (F8) projects the whole matrix.
  Mat3 r_cov{Mat3::Identity()};
  double k_sigma{0.05};     // largest 1 sigma of the strengths: k_sigma x each jet's torque
};

struct FaultDetectorStatus {
  Vec3 residual{Vec3::Zero()};  // last window: measured minus predicted rate change, rad/s
  double chi2{0.0};             // its no-fault chi-square (3 dof)
  double noise_sigma{0.0};      // per-axis residual 1 sigma of the last window
  std::uint16_t suspected_on{0};   // bit i: thruster i stuck-on is the leading hypothesis
  std::uint16_t suspected_off{0};
  std::uint16_t confirmed_on{0};   // latched
  std::uint16_t confirmed_off{0};
  std::uint16_t confirmed_degraded{0};  // latched (F18); the strength factors are strength_factor()
  int best{-1};                 // leading hypothesis: 0..15 stuck-on, 16..31 stuck-off, -1 none
  double best_llr{0.0};
  double runner_up_llr{0.0};
  std::uint32_t windows{0};
  std::uint32_t suspicions{0};  // windows whose chi-square exceeded suspect_chi2
  std::uint32_t models_held{0};  // model refreshes not applied while a hypothesis was suspected
  int probe_pod{-1};              // (F9) pod whose valve the detector asks closed for a test, -1 none
  std::uint32_t probes{0};        // isolation tests started
  std::uint32_t episode_restarts{0};  // (F25) episodes restarted with a new suspected leader
  int ambiguous_with{-1};         // the alternative the leader could not be told from, -1 none
  // (F14) The identifier's evidence: the thruster whose stuck-on torque it matches best (-1 none)
  // and how many fitted windows in a row it has passed the isolation test.
  int identified_best{-1};
  int identified_streak{0};
  std::uint32_t identified_confirmations{0};  // faults confirmed through (F14)
  std::uint32_t sweeps{0};                    // (F17) pod sweeps started
  std::uint32_t sweep_confirmations{0};       // faults confirmed through (F17)
  std::uint32_t degraded_confirmations{0};    // partial losses confirmed through (F18)
  int check_jet{-1};                          // (F19) the jet being checked, -1 none
  std::uint32_t checks{0};                    // (F19) jet checks started
  std::uint32_t checks_unfit{0};              // (F19) check windows not scored (model error)
  std::uint32_t surveys{0};                   // (F36) of the checks, those started by the survey
  std::uint32_t survey_ratings{0};  // (F36) due jets rated against the check gates (<= 1 a decision)
  std::uint32_t survey_kick_refusals{0};  // (F44) due jets not surveyed: the check would kick the rate
  std::uint32_t evidence_kick_refusals{0};  // (F56) evidence checks not flown after a fault: kick
  std::uint32_t survey_noise_refusals{0};  // (F48) due jets not surveyed: the gyro too noisy
  std::uint32_t long_checks{0};  // (F49) of the checks, those flown as one long window
  std::uint32_t long_checks_dropped{0};  // (F49) ended by an early suspicion off their jet
  std::uint32_t long_checks_capped{0};  // (F50) evidence checks flown at check_long_reach E_cap
  std::uint16_t unverified{0};  // (F36) bit i: thruster i commanded since it was last verified
  std::uint32_t early_detections{0};  // (F33) suspicions raised before their window closed
  std::uint32_t onset_restarts{0};  // (F45) onset windows ended at their early suspicion
  std::uint32_t probe_whole_windows{0};  // (F47) tests flown on a whole window, weak evidence
  std::uint32_t elsewhere_verdicts{0};  // (F40) tests whose closed windows named another pod's jet
  int balance_channel{-1};            // (F61) the channel under a balance test, -1 none
  std::uint32_t balance_tests{0};     // (F61) balance tests flown (started)
  std::uint32_t balance_confirmations{0};  // (F61) faults confirmed by a balance test
  std::uint32_t balance_inconclusive{0};   // (F61) channels left undecided after balance.max_tests
  std::uint32_t balance_aborted{0};        // (F61) tests broken by a gap, a valve or a latch
  double balance_chi2{0.0};           // (F61) the last test's |g+ + g-|^2 / var
  double balance_ratio{1.0};          // (F61) ... and its weaker half's strength ratio
};

// Raised by update(); the caller turns them into events.
struct FaultEvents {
  bool suspected{false};       // a window crossed suspect_chi2 with no fault confirmed yet
  bool early{false};           // (F33) ... a window still open: no hypothesis ranked on it yet
  bool confirmed{false};       // a fault was confirmed this tick
  int thruster{-1};
  FaultKind kind{FaultKind::kNone};
  double factor{0.0};  // kDegraded: the strength factor now latched (0 < factor < 1)
  double factor_sigma{0.0};  // ... its 1 sigma from the fit (F18)
};

class FaultDetector {
 public:
  void configure(const FaultDetectorParams& p, const RcsLayout& rcs, double u_max, double dt);
  void reset();  // scores and windows; latched faults are kept (clear() removes them)
  void set_model(const FaultModel& m);
  // (F10) A closed window is being evaluated: the next update runs one step of it.
  bool evaluating() const { return eval_phase_ != 0; }
  // The next update runs one of the evaluation's heavy steps: the two scoring steps (the second
  // with the cross sums), and, when a hypothesis is past the confirmation level, step 3 (the
  // rest of its bias-bounded margins (F8) against every alternative, begun in step 2) and the
  // decision (it may start an isolation test), or the decision when a pod sweep reads its step
  // (F17), and the partial-loss step (F18) after the decision. The executive keeps other periodic
  // work off those ticks.
  bool heavy_step_next() const {
    return eval_phase_ == 1 || eval_phase_ == 2 || (eval_phase_ == 0 && partial_loss_pending_) ||
           (eval_phase_ == 3 && (st_.best_llr > p_.confirm_llr || balance_.evaluate_pending())) ||
           (eval_phase_ == 4 && (st_.best_llr > p_.confirm_llr || sweeping())) ||
           // (F61) the fit of a balance test on a step that carries no other (with windows of
           // five updates the closed window's evaluation and the partial-loss step take every
           // update but the third step's when no leader is past the confirmation level)
           (eval_phase_ == 0 && !partial_loss_pending_ && balance_.evaluate_pending());
  }
  // The steps up to the decision; with the partial-loss confirmation (F18) on, its step follows on
  // the next update that carries none of them.
  static constexpr int kEvaluationSteps = 4;
  FaultEvents update(const FaultDetectorInput& in);

  // Ground overrides and what the flight does after isolation.
  // Latches it (as if confirmed). kDegraded: the thruster delivers `factor` (0, 1] of its
  // model's thrust from now on (a factor of 1 or out of range leaves it healthy).
  void declare(int thruster, FaultKind kind, double factor = 1.0);
  void clear(int thruster);                    // -1: every thruster
  // Adds the counters of `before` (a status of this detector before it was configured again) to
  // this one's: the flight reconfigures the detector with every table it takes (a model adoption,
  // an uplink), and its counts in telemetry are the flight's, not the configuration's. The window
  // count, to which the checks' intervals are kept, and the state start afresh.
  void carry_counts(const FaultDetectorStatus& before);
  // (F14) Evidence from the identifier's fault torque, after each of its windows. A stuck-on it
  // isolates is confirmed on the next update (the same event and latch as (F6)).
  void identified_evidence(const StuckOnEvidence& e);
  const FaultDetectorStatus& status() const { return st_; }
  std::uint16_t confirmed_on() const { return st_.confirmed_on; }
  std::uint16_t confirmed_off() const { return st_.confirmed_off; }
  std::uint16_t confirmed_degraded() const { return st_.confirmed_degraded; }
  // (F18) The latched strength factor of thruster i: 1 unless it is confirmed degraded. The
  // detector predicts the thruster at factor x its model's thrust; the flight allocates with it.
  double strength_factor(int i) const { return factor_[static_cast<std::size_t>(i)]; }
  const FaultDetectorParams& params() const { return p_; }
  // A hypothesis is suspected (its score above half the confirmation level): the model it is
  // tested against is held (F7), and the identifier should not absorb the fault either.
  bool suspecting() const { return suspecting_ || deg_suspecting_; }
  // (F17) A pod sweep is under way: the identifier's windows are not fitted meanwhile (its fault
  // torque d is constant only while every valve stays as it is).
  bool sweeping() const { return sweep_next_ >= 0; }
  // (F9) The pod whose latch valve the detector asks to be closed for an isolation test (-1 none).
  int probe_pod() const { return st_.probe_pod; }
  // (F19) The thruster the detector asks to be fired for a jet check (-1 none), and at what
  // force (N, produced).
  int check_jet() const { return st_.check_jet; }
  double check_force() const { return check_force_; }  // (F49: the long check's own)
  // (F51) The model's relative 1 sigma of thruster i's fitted loss: its signature's error along
  // itself (strength, inertia, and the centre of mass's covariance for the jet alone and for its
  // check's move, the larger).
  double loss_rel_error(int i) const;
  // (F23) The fitted loss at and above which thruster i's loss is total (stuck off): 1 less
  // model_sigmas of its signature's relative error, the gap at most kMaxTotalLossGap.
  static constexpr double kMaxTotalLossGap = 0.25;
  double total_loss_floor(int i) const;
  // (F19, F42) The check's move of the channel forces for channel c, unscaled (du(c) in (0, 1]):
  // the minimum-norm move with no torque on the detector's model, whose channel torques are
  // (p + r_hat) x d with the identified centre of mass. False when channel c has no such move.
  bool check_move(int c, Vec8& du) const;
  // (F55) The channels a check's move holds (bit j: channel j): a half latched stuck on or off,
  // or its pod's valve closed in this update's input.
  std::uint8_t held_channels() const;
  bool check_on_model() const { return p_.check_model_null_space; }
  // (F61) The channel under a balance test (-1 none) and the signed force it adds there over the
  // next interval (N). A test whose last sample is in is no longer flown: the flight takes control
  // again on that update, whenever its fit runs.
  int balance_channel() const { return balance_.flying() ? balance_.channel() : -1; }
  double balance_command() const { return balance_.command(); }
  const ChannelBalanceTest& balance_test() const { return balance_; }
  // ... the same as physical thruster forces (N): thruster 2c ("+") or 2c + 1 ("-").
  Vec16 balance_thrust() const {
    Vec16 f = Vec16::Zero();
    const int c = balance_.channel();
    const double u = balance_.command();
    if (c >= 0 && u > 0.0) f(2 * c) = u;
    if (c >= 0 && u < 0.0) f(2 * c + 1) = -u;
    return f;
  }

  // Rate change signature of hypothesis h over the last window (exposed for tests): 0..15
  // stuck-on of thruster h, 16..31 stuck-off of thruster h - 16.
  const Vec3& signature(int h) const { return sig_[static_cast<std::size_t>(h)]; }
  static constexpr int kHypotheses = 2 * kThrusters;

 private:
  void close_window();
  void start_window(const Vec3& omega);
  void cancel_evaluation();
  void reset_episode();
  // The alternative that the leader h cannot yet be told from under (F6)/(F8), or -1 (exposed to
  // close_window only).
  int blocking_alternative(int h) const;
  // The scan behind it over alternatives [g_begin, g_end), continuing `scan` (split over
  // evaluation steps 2 and 3 at kScanSplit, F10: step 2 also scores and ranks, so it takes the
  // smaller part).
  static constexpr int kScanSplit = 12;
  struct BlockingScan {
    int h{-1};  // the leader scanned for (-1: no scan under way)
    int worst{-1};
    double worst_lead{0.0};
  };
  void blocking_scan(int h, int g_begin, int g_end, BlockingScan& scan) const;
  int partial_loss_rival(int h) const;  // (F13, F25) the other jet whose partial loss h does not beat
  BlockingScan block_scan_{};
  // (F61) The balance test: its sample of this update (the other jets' predicted motion), its
  // start, and a window flown under it (not scored: its firings are the test's).
  void balance_update(const FaultDetectorInput& in, const Vec3& thrust_rate, const Vec3& gyro);
  void balance_start(const FaultDetectorInput& in);
  void balance_verdict(const BalanceVerdict& v);
  ChannelBalanceTest balance_{};
  double balance_clock_s_{0.0};  // (F61) flight time since configure, for the rounds' interval
  bool eval_balance_{false};     // (F61) the window under evaluation flew a balance test
  // (F13) For a stuck-off leader h: the jet whose partial loss of thrust explains the episode
  // as well (within margin_llr), h itself when its amplitude is that of a partial loss, or -1.
  int partial_loss_alternative(int h) const;
  // (F13) The episode's LLR of hypothesis g (16..31) as a partial loss of thrust, fitted in (0, 1].
  double partial_loss_llr(int g) const;
  // (F13) The episode's signature energy E_g = |b_g|^2 A_g of hypothesis g (16..31).
  double partial_loss_energy(int g) const;
  // (F58) Whether sums SR, E of thruster i's fit put its loss total_loss_sigmas of the fit's
  // 1 sigma below the total-loss floor (false when total_loss_sigmas is 0).
  bool below_total_loss(int i, double sr, double e) const;
  // (F59) A jet is latched (confirmed or declared) and the model's inertia is not known to
  // after_fault_max_j_rel: no stuck-off or partial-loss confirmation, no check.
  bool after_fault_unconfident() const;
  // (F13, F18, F23) Whether sums SR, E of thruster i's partial-loss fit say a partial loss: the
  // fitted loss below the floor, and the fit margin_llr better than a loss at the floor.
  bool partial_not_total(int i, double sr, double e) const;
  // (F18, F19) The model's relative 1 sigma of thruster i's signature b_i.
  double signature_rel_error(int i) const;
  // (F24) The stuck-off LLR a check of thruster i is expected to move, E / 2 over its windows.
  double expected_check_llr(int i) const;
  // (F24, F36) The stuck-off energy E one window of a check of thruster i is expected to have.
  // kick_rate (optional): the 1 sigma rate the check's firing puts on the body per second of it
  // (F44), from the model's error against the check's move.
  double expected_check_energy(int i, double* kick_rate = nullptr) const;
  // (F36) Each jet's stuck-off energy since it was last verified, after each decision.
  void update_survey();
  // (F36) The jet the survey checks now (-1 none) and the check's windows; a due jet that cannot
  // be checked now is put back by check_interval_s.
  int survey_candidate(int& windows);
  // (F18) Thruster g's partial-loss LLR over its CUSUM's segment, its loss fitted (0: no segment).
  double degraded_llr(int g) const;
  // (F18) The jet to confirm degraded now (and its fitted loss), or -1.
  int degraded_candidate(double& loss) const;
  void evaluate_partial_losses();
  // (F19) After each decision: the jet check under way counts its windows; otherwise one starts
  // for the jet with the most stuck-off or partial-loss evidence, when it reaches check_llr.
  void update_check();
  void end_check() {
    st_.check_jet = -1;
    check_left_ = 0;
    check_long_n_ = 0;
    long_start_ = false;
  }
  // (F49) Long checks: whether they fly now, and the force of one of thruster i (0: none within
  // the gates).
  bool long_mode() const {
    return p_.check_long_ticks > 0 && survey_noisy_ && survey_allowed_;
  }
  // energy: the check's expected stuck-off energy; kick_gates: F44's and F48's bounds apply;
  // capped (F50, may be null): an energy above check_long_reach of its cap is flown at that
  // fraction of the cap, when that is at least check_long_energy, and *capped is set.
  double long_check_force(int i, double energy, bool kick_gates, bool* capped = nullptr) const;
  // (F44) The rms rate per second that the model's error leaves of the check's move du, per unit
  // of du.
  double move_kick_rate(const Vec8& du) const;
  double check_force_{100.0};  // the force of the check under way (check_force_n, or F49's)
  int check_long_n_{0};        // (F49) the samples of the long check under way, 0 none
  bool long_start_{false};     // (F49) its window starts on the next valid sample
  double candidate_force_{0.0};  // (F49) the survey candidate's long-check force
  int check_left_{0};
  double quiet_var_{0.0};   // (F24) the residual variance of the last window flown without a check
  int check_prev_{-1};      // the jet checked on the previous update (its thrust is this one's)
  bool eval_unfit_{false};  // the evaluated window's check showed a model error: not scored
  Vec3 eval_slope_{Vec3::Zero()};  // (F31) the evaluated window's residual slope ...
  double eval_stt_{0.0};           // ... and its time spread (check_normal_chi2's inputs)
  bool eval_onset_{false};  // (F21) the evaluated window is the one a fault started in: not scored
  bool last_suspicious_{false};  // (F21) the window before it exceeded suspect_chi2
  std::array<std::uint32_t, kThrusters> last_check_{};  // window count at each jet's last check, +1
  std::array<std::uint8_t, kThrusters> check_backoff_{};  // doublings of each jet's interval (0..2)
  std::array<double, kThrusters> survey_e_{};  // (F36) stuck-off energy since last verified
  bool survey_allowed_{true};  // (F43) this update's FaultDetectorInput::survey_allowed
  // (F55) The pods' latch valves of this update's input: a check's move holds their channels.
  std::array<bool, kPods> valve_open_{{true, true, true, true}};
  bool survey_noisy_{false};  // (F48) the gyro too noisy for a survey check within its kick bound
  std::array<std::uint32_t, kThrusters> survey_from_{};  // (F36) window count when last verified
  // (F57) Window count + 1 at each jet's last survey due to its partial-loss evidence (0: none).
  std::array<std::uint32_t, kThrusters> loss_survey_at_{};
  bool survey_loss_evidence(std::size_t k) const;  // (F57) CUSUM in [survey_loss_llr, check_llr)
  FaultEvents step(const FaultDetectorInput& in);  // update() with the delivered thrust
  std::array<double, kThrusters> window_energy_{};  // (F18) each stuck-off's E of the window
  bool deg_suspecting_{false};  // (F18) a partial loss past half the confirmation level
  bool partial_loss_pending_{false};  // (F18) its step is due (after the decision)
  FaultDetectorInput scaled_{};  // (F18) the input with degraded jets at their factor
  std::array<double, kThrusters> deg_cusum_{};  // (F18) partial-loss CUSUM per thruster
  std::array<double, kThrusters> deg_sr_{};     // ... its segment's sum S~.r~ / var
  std::array<double, kThrusters> deg_e_{};      // ... and sum |S~|^2 / var
  std::array<double, kThrusters> factor_ = [] {  // (F18) latched strength factors, 1 healthy
    std::array<double, kThrusters> a{};
    a.fill(1.0);
    return a;
  }();

  FaultDetectorParams p_{};
  double u_max_{200.0};
  double dt_{0.1};
  std::array<Vec3, kThrusters> pos_{};
  std::array<Vec3, kThrusters> dir_{};
  std::array<int, kThrusters> pod_{};
  FaultModel m_{};
  double r_sigma_{1.0};  // sqrt of the largest diagonal element of m_.r_cov
  Mat3 j_inv_{Mat3::Identity()};
  double j_inv_norm_{1.0};
  double j_norm_{1.0};

  // Every c_h is a combination of 20 basis ramps (F4): x_i = c of "i stuck off" (16) and the open
  // time of each pod (4), c_{i on} = u_max x_{16+pod(i)} + x_i. Per tick only the basis's cross
  // sums are accumulated (210, not the 496 pairs of hypotheses).
  static constexpr int kBasis = kThrusters + kPods;
  static constexpr int kBasisPairs = kBasis * (kBasis + 1) / 2;
  static constexpr int basis_index(int a, int b) {  // a <= b
    return a * (2 * kBasis - a + 1) / 2 + (b - a);
  }

  // Window accumulation (F2)-(F5): samples j = 1..n after the window's first sample. Two sets:
  // one accumulates the open window while the other, closed, is evaluated over the next ticks
  // (F10). The arrays are assigned on a window's first sample, never cleared.
  struct WindowSums {
    int n{0};
    double motion{0.0};         // cumulative |predicted terms| * dt (model-uncertainty scale)
    double force_impulse{0.0};  // cumulative sum of thrust * dt over the jets, N s
    double thrust_motion{0.0};  // cumulative |thrust rate change| * dt
    double gross_motion{0.0};   // (F35) thrust_motion with sum |b_i| f_i on the checked updates
    Vec3 sum_r{Vec3::Zero()};   // sum of residuals r_j
    double sum_t{0.0};          // sum of j (sample index), for the slope test
    double sum_tt{0.0};
    Vec3 sum_tr{Vec3::Zero()};
    // The signature of hypothesis h is S_h(j) = b_i c_h(j) with the scalar c_h(j) = sum of the
    // extra (stuck-on: u_max - f) or missing (stuck-off: -f) thrust times dt up to sample j, so
    // the window's sums need only scalars and one vector per hypothesis (F5).
    std::array<double, kHypotheses> c{};
    std::array<double, kHypotheses> sum_c{};
    std::array<double, kHypotheses> sum_cc{};
    std::array<double, kHypotheses> sum_crx{};  // sum of c_h(j) r_j, by component
    std::array<double, kHypotheses> sum_cry{};
    std::array<double, kHypotheses> sum_crz{};
    std::array<double, kPods> tp{};      // open time of each pod since the window's start
    std::array<double, kPods> sum_tp{};  // its sum over the window's samples
    // sum_j x_a x_b; row a is written only once ramp a is non-zero (bit a of `live`): a ramp
    // that stays zero all window contributes nothing and its row is not read.
    std::array<double, kBasisPairs> sum_xx{};
    std::uint32_t live{0};
    int check_jet{-1};  // (F19) the jet checked during the window, -1 none
    bool early_suspected{false};  // (F33) its suspicion was raised before it closed
    bool balance{false};          // (F61) a balance test flew within it
  };
  template <bool kFirst>
  void accumulate(WindowSums& w, const FaultDetectorInput& in, const Vec3& r);
  // (F10) One step of the closed window's evaluation: 1 the noise and the stuck-on scores, 2 the
  // stuck-off scores and the ranking, 3 the episode's cross sums, 4 the decision.
  void evaluate_step();
  void evaluate_noise(const WindowSums& w);
  // (F5) The variance of a residual sample over the window's first n samples, and (F33) the
  // no-fault slope statistic of those samples.
  // gross: (F35) the thrust's share of the model's error from every jet's torque, not the net.
  double window_var(const WindowSums& w, double n, bool gross = false) const;
  double early_chi2(const WindowSums& w, double n) const;
  void evaluate_scores(const WindowSums& w, int first, int last);
  void rank_hypotheses();
  void evaluate_cross(const WindowSums& w);
  void decide();
  void apply_model(const FaultModel& m);

  int n_{0};
  bool have_start_{false};
  Vec3 omega_start_{Vec3::Zero()};  // rate at the window's first sample
  Vec3 omega_prev_{Vec3::Zero()};
  Vec3 predicted_{Vec3::Zero()};    // cumulative predicted rate change since the start
  std::array<WindowSums, 2> win_{};
  int acc_{0};         // the set the open window accumulates into
  int eval_phase_{0};  // next step of the closed window's evaluation (1..4), 0 none
  double eval_var_{1.0};  // the closed window's residual variance (F5)
  bool model_staged_{false};  // a model that arrived during an evaluation, applied after it
  FaultModel staged_{};
  std::array<Vec3, kHypotheses> sig_{};  // b c of the last window, for signature()
  // (F1) J^-1 k_i (p_i + r) x e_i: rate change per N s of thruster i.
  std::array<Vec3, kThrusters> b_{};
  std::array<double, kThrusters> b_norm_{};  // |b_i| (F35)

  std::array<double, kHypotheses> score_{};
  // (F11) Windows in which a hypothesis's signature was too weak to score on its own are pooled:
  // their LLRs and signature energies add up until the pooled energy reaches min_signature, and
  // the pool is then scored as one window.
  std::array<double, kHypotheses> pool_llr_{};
  std::array<double, kHypotheses> pool_energy_{};
  void reset_scores();
  bool suspecting_{false};  // some score above half the confirmation level (F7)
  int runner_up_{-1};       // the runner-up of the last scored window
  // (F8) Since the current episode began (the last window with every score at zero): the
  // unfloored cumulative LLR of each hypothesis, its information A_h = sum |c~_h|^2 / var, and the
  // cross terms C_hg = sum c~_h c~_g / var, kept as the basis's (cross_basis()).
  std::array<double, kHypotheses> lambda_{};
  std::array<double, kHypotheses> info_{};
  double cross(int h, int g) const;
  std::array<double, kBasisPairs> cross_xx_{};  // per episode: sum_w (sum x~_a x~_b) / var
  // The episode's epoch and each hypothesis's and each basis row's: an entry whose epoch is not
  // the episode's is stale, read as zero and written afresh (reset_episode clears nothing).
  std::uint32_t episode_epoch_{1};
  std::array<std::uint32_t, kHypotheses> hyp_epoch_{};
  std::array<std::uint32_t, kBasis> row_epoch_{};
  std::array<double, kHypotheses> window_info_{};  // the evaluated window's |c~_h|^2 / var
  void restart_episode_with_window();  // (F25)
  double lambda(std::size_t k) const { return hyp_epoch_[k] == episode_epoch_ ? lambda_[k] : 0.0; }
  double info(std::size_t k) const { return hyp_epoch_[k] == episode_epoch_ ? info_[k] : 0.0; }
  int ambiguous_windows_{0};
  int probe_left_{0};
  // (F15) The isolation test's outcome: the tested pod, how many windows were flown with it closed
  // throughout, and the verdict awaited from the first window after it reopens.
  int probe_tested_pod_{-1};
  bool probe_early_{false};  // (F52) the test under way started below confirm_llr
  // (F52) Whether a test's verdict may name stuck-on thruster h (its score past confirm_llr after
  // an early test).
  bool verdict_allowed(int h) const {
    return !probe_early_ || (h >= 0 && score_[static_cast<std::size_t>(h)] > p_.confirm_llr);
  }
  int probe_closed_{0};
  bool verdict_pending_{false};
  int window_len_{5};  // (F46) the samples of the window under way (window_ticks or a test's)
  bool probe_short_{true};  // (F47) the test under way flies the short window (F46)
  bool restart_window_{false};  // (F27) the next sample starts a new window
  double eval_open_fraction_{1.0};           // the evaluated window's open time of the tested pod
  std::array<double, kHypotheses> window_llr_{};  // the evaluated window's LLR per hypothesis
  void end_probe_verdict() {
    probe_tested_pod_ = -1;
    probe_closed_ = 0;
    verdict_pending_ = false;
    probe_early_ = false;
  }
  // (F15) The stuck-on hypothesis confirmed by a test's outcome, or -1.
  int probe_verdict() const;
  // (F39) After a test's closed windows, the leader is a stuck-on jet of another pod that they
  // favour.
  bool closed_leads_elsewhere() const;
  int tested_pod_leader(const std::array<double, kHypotheses>& llr, double& best_llr) const;
  // (F16) The tests' likelihood: each hypothesis's LLR summed over every window flown during the
  // isolation tests of one pod (closed windows and reopened ones, consecutive tests of that pod
  // adding up), and the pod (-1 none). A stuck-on jet of another pod loses ½E in each quiet closed
  // window; one of the tested pod loses nothing there.
  std::array<double, kHypotheses> probe_llr_{};
  // (F29) ... and each jet's stuck-off energy over the same windows, for its partial loss.
  std::array<double, kThrusters> probe_energy_{};
  int probe_llr_pod_{-1};
  // (F32) The window that started the test (its LLR and stuck-off energy per hypothesis), the
  // alternative that blocked its leader, and the sums over this test's windows flown closed
  // throughout.
  std::array<double, kHypotheses> trigger_llr_{};
  std::array<double, kThrusters> trigger_energy_{};
  std::array<double, kHypotheses> closed_llr_{};
  std::array<double, kThrusters> closed_energy_{};
  int probe_blocker_{-1};
  int closed_probe_verdict() const;
  int closed_verdict_elsewhere() const;
  bool beats_closed_partial_losses(double llr) const;
  void reset_probe_llr() {
    probe_llr_.fill(0.0);
    probe_energy_.fill(0.0);
    probe_llr_pod_ = -1;
  }
  // (F17) Pod sweep on the identifier's fault torque: the pods in test order, the next one
  // (-1: no sweep), the tested pod's closed windows still to fly (0: reading or idle), and the
  // step test's sums: the reference window's unexplained acceleration and each jet's mean excess
  // thrust, the closed windows' sum, and their variances (rad/s^2)^2.
  static constexpr int kSweepRepeats = 8;
  std::array<int, kPods> sweep_order_{};
  int sweep_next_{-1};
  int sweep_pod_{-1};
  int sweep_left_{0};
  bool sweep_reading_{false};
  int sweep_closed_{0};
  Vec3 sweep_ref_{Vec3::Zero()};
  Vec3 sweep_closed_sum_{Vec3::Zero()};
  std::array<double, kThrusters> sweep_ref_excess_{};
  double sweep_ref_var_{0.0};
  double sweep_closed_var_{0.0};
  std::array<double, kThrusters> sweep_ref_force_{};     // delivered mean thrust, reference
  std::array<double, kThrusters> sweep_closed_force_{};  // ... summed over the closed windows
  std::array<double, kThrusters> sweep_llr_{};  // each jet's L summed over the sweeps' tests
  std::array<double, kThrusters> sweep_llr_off_{};  // ... of each jet stuck off
  // The evaluated window's unexplained acceleration, its gyro variance, each jet's mean excess
  // thrust (u_max - f over the open time, per second of window, N) and each pod's open fraction.
  Vec3 eval_accel_{Vec3::Zero()};
  double eval_accel_var_{0.0};
  std::array<double, kThrusters> eval_excess_{};
  std::array<double, kPods> eval_open_{};
  void end_sweep() {
    sweep_next_ = -1;
    sweep_pod_ = -1;
    sweep_left_ = 0;
    sweep_reading_ = false;
  }
  // (F17) One step of the sweep at a window's decision; true when it confirmed a jet.
  bool sweep_step();
  struct SweepLeader {
    int jet{-1};  // -1: every jet latched
    double first{-1e300};
    double second{-1e300};
  };
  SweepLeader sweep_leader() const;
  FaultDetectorStatus st_{};
  FaultEvents pending_{};
  int identified_confirm_{-1};  // (F14) thruster to confirm stuck on at the next update
};

}  // namespace rocksteady::gnc
