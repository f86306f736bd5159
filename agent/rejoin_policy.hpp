#pragma once
// When an agent process joins DDS again, how patient its next participant is
// for the scene and whether it keeps the shared-memory transport: a pure
// rule, free of DDS and clocks (agent/main.cpp's join loop applies it).

namespace ddswarm::agent {

/// Under DDS Security the server authenticates every agent of the swarm, and
/// on a loaded machine their handshakes queue: a handshake may take this long
/// per drone of the scenario before it counts as stalled, and a secure agent
/// with the scene waits as long for the swarm state (JoinPatience::deaf_s).
/// At 128 secure drones on 2 cores the 10 s default made 107 agents join
/// again in one bring-up, each a handshake more, and the swarm never came up;
/// at 0.5 s a drone (64 s) 12 agents still heard no swarm state in time; with
/// 90 s the swarm took off (docs/security.md, "Large secure swarms").
inline constexpr double kHandshakeSecondsPerDrone = 0.75;

/// agent.handshake_timeout_s as a swarm of `drones` uses it: 0 stays 0
/// (never), any other value is at least kHandshakeSecondsPerDrone * drones.
double handshake_timeout_for(double handshake_timeout_s, int drones);

class RejoinPolicy {
 public:
  /// A join right after one that had the scene (the swarm is up) waits at
  /// most this many DDS leases for the scene.
  static constexpr double kRejoinedSceneLeases = 4.0;

  /// rejoin_after_s: agent.rejoin_after_s (0 = never re-join for want of a
  /// scene); lease_s: dds.lease_duration_s; shm_transport: whether the
  /// user's configuration uses the shared-memory transport;
  /// handshake_timeout_s: agent.handshake_timeout_s (0 = never).
  RejoinPolicy(double rejoin_after_s, double lease_s, bool shm_transport,
               double handshake_timeout_s = 0)
      : rejoin_after_s_(rejoin_after_s),
        lease_s_(lease_s),
        handshake_s_(handshake_timeout_s),
        shm_(shm_transport) {}

  /// The next join's scene wait (its agent.rejoin_after_s). Each join in a
  /// row that heard no scene waits twice as long as the one before
  /// (rejoin_patience_s), except right after a join that had the scene.
  double scene_wait_s() const;
  /// The next join's agent.handshake_timeout_s: twice as long after each
  /// join in a row that ended so (handshake_stall), at most 8 times.
  double handshake_wait_s() const;
  /// Whether the next join uses the shared-memory transport.
  bool shm_transport() const { return shm_; }

  /// How the join that scene_wait_s() planned ended. cut_off: the server did
  /// not hear it, or it did not hear the server (kUnheard, kDeaf); no_scene:
  /// no scene within its wait (kNoScene); heard_scene: it had the scene;
  /// handshake_stall: a secure server's handshake with it did not end
  /// (kHandshakeStall).
  /// Returns true when this end turns the shared-memory transport off for
  /// every later join: Fast DDS 2.9 can leave the server listening on
  /// shared-memory ports whose files a stall made anew and removed, which
  /// no new sender reaches, while UDP reaches it (docs/dds.md).
  bool ended(bool cut_off, bool no_scene, bool heard_scene, bool handshake_stall = false);
  /// This process was started again (restart_on_dead_owner_lock) while it
  /// flew in a swarm: its first join is a re-join after one that had the
  /// scene, so it waits kRejoinedSceneLeases leases for the scene, not the
  /// start-up wait (40-60 s, longer than a ground station waits for it).
  void started_again() { had_scene_ = true; }

 private:
  double rejoin_after_s_, lease_s_, handshake_s_;
  bool shm_;
  int no_scene_ = 0;          ///< joins in a row that heard no scene
  int handshake_stalls_ = 0;  ///< joins in a row that ended in kHandshakeStall
  bool had_scene_ = false;    ///< the last join had the scene
};

}  // namespace ddswarm::agent
