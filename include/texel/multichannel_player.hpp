// The multi-channel player (docs/rendering.md "Multi-channel", docs/player.md):
// one Player per channel (texel/multichannel.hpp's Channel), fed the same
// finger. Channel c's player reads its own map at the finger's position +
// the actuator's offset and limits its output to the actuator's response, so
// everything a Player guarantees (band limit at the finger's speed, touch
// ramps, crossfades, no allocation in process) holds per channel unchanged.
//
// The trade-off: N players repeat the finger tracking N times (a few
// multiplications per sample each) instead of sharing one track; in return a
// channel is exactly a 1-D Player and nothing of the real-time path is new.
//
// config → prepare → process: the constructor allocates every player, its
// rings and a planar scratch block of `max_block` frames per channel;
// process() writes caller memory only.
//
// It is a PlayerBase, so the backends drive it (sinks.hpp: the null and the
// PortAudio backend opened with as many channels, AudioOptions::channels):
// PlayerBase::process's buffer is then frames × channels, interleaved.
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "texel/finger.hpp"
#include "texel/multichannel.hpp"
#include "texel/player.hpp"

namespace texel {

class ChannelPlayer final : public PlayerBase {
 public:
  /// prepare: one Player per channel with `config` (its response replaced
  /// by the channel's), playing the channel's surface (none: silence).
  /// `max_block`: the most frames one process() call writes per channel
  /// before it loops (the scratch block's size), 1 … 65536.
  /// Throws InvalidArgument for no channels or an invalid config.
  ChannelPlayer(const PlayerConfig& config, std::span<const Channel> channels, std::size_t max_block = 1024);
  /// Stops an attached driver first (see player.hpp "Lifetime"), then frees every player.
  ~ChannelPlayer() override;

  [[nodiscard]] std::size_t channels() const { return players_.size(); }
  /// Channel c's player (its statistics; control-thread calls such as set_gain).
  [[nodiscard]] Player& player(std::size_t c) { return *players_.at(c); }

  // -------------------------------------------------------- control thread
  /// Queues a finger sample on every channel (shifted by each actuator's
  /// offset): all or none, false if any channel's queue is full.
  bool push(const FingerSample& s);
  /// Swaps in one map per channel (maps.size() == channels(), none null; a
  /// channel at rest is given a silent map, e.g. one sample of 0): each
  /// channel's Player crossfades to its map as Player::set_map does, so a
  /// stimulus switch on a multi-actuator display is N crossfades. `offsets`
  /// (empty: unchanged) as set_offsets. The channels take their maps at the
  /// start of a block each, so they begin their crossfades in the same
  /// block, or one block apart when the swap lands while process() is
  /// between channels. Throws InvalidArgument (nothing swapped) for a wrong
  /// count, a null map or an offset out of range. Control thread; allocates
  /// nothing itself, frees retired maps.
  void set_maps(std::vector<std::unique_ptr<const PlayerMap>> maps, std::span<const Millimetres> offsets = {});
  /// Replaces the actuators' offsets (one per channel, −50 … 50 mm) for the
  /// finger samples pushed from now on: a document of another device brings
  /// its own actuators. Samples already queued keep the offsets they were
  /// pushed with. push() reads them: call it on the thread that pushes (or
  /// under the lock it pushes under). Throws InvalidArgument (nothing
  /// changed) for a wrong count or an offset out of range.
  void set_offsets(std::span<const Millimetres> offsets);
  /// The actuators' offsets in force for pushed samples (mm), one per channel.
  [[nodiscard]] std::span<const double> offsets_mm() const { return offsets_; }
  /// Frees the maps the players have retired. Returns how many.
  std::size_t collect() override;

  // ------------------------------------------------------- real-time thread
  /// Fills one buffer per channel (outs[c], all the same size) with the next
  /// frames; `position_mm` (empty, or that size) receives the finger's own
  /// position for each frame (without any actuator's offset).
  ///
  /// Real-time safe: never allocates, frees, locks, logs, throws or does
  /// I/O (each channel is a Player::process call); bounded work per sample
  /// and channel.
  /// Returns channel 0's block information with the peak over every channel.
  BlockInfo process_planar(std::span<const std::span<float>> outs, std::span<float> position_mm = {}) noexcept;
  /// The same into one interleaved buffer: out[i·N + c] is channel c's frame
  /// i (out.size() a multiple of N; a remainder is left untouched), through
  /// the scratch block; `position_mm` empty or out.size() / N long. What a
  /// backend calls (PlayerBase). Real-time safe as process_planar().
  BlockInfo process(std::span<float> out, std::span<float> position_mm = {}) noexcept override;

 private:
  void check_offsets(std::span<const Millimetres> offsets) const;
  std::vector<std::unique_ptr<Player>> players_;
  std::vector<double> offsets_;  // mm, per channel
  std::vector<float> scratch_;   // max_block_ frames × channels, planar
  std::vector<float> scratch_position_;
  std::size_t max_block_;
  std::uint64_t frames_ = 0;  // frames produced (real-time thread)
};

/// Off-line rendering of a whole trace on every channel (render_trace per
/// channel, in lockstep blocks): returns frames × channels samples,
/// interleaved; `positions`, if given, receives the finger's position
/// (without offsets) for each frame.
std::vector<float> render_trace_channels(std::span<const Channel> channels, const PlayerConfig& config,
                                         std::span<const FingerSample> trace, std::size_t frames,
                                         std::vector<float>* positions = nullptr, std::size_t block = 64);

}  // namespace texel
