// The multi-channel player: one Player per channel (texel/multichannel_player.hpp).
#include "texel/multichannel_player.hpp"

#include <algorithm>
#include <cmath>

#include "texel/detail/format.hpp"
#include "texel/error.hpp"

namespace texel {

ChannelPlayer::ChannelPlayer(const PlayerConfig& config, std::span<const Channel> channels, std::size_t max_block)
    : PlayerBase(config.rate_hz), max_block_(max_block) {
  if (channels.empty()) throw InvalidArgument("ChannelPlayer: no channels; allowed: 1 … " + std::to_string(max_actuators));
  if (max_block < 1 || max_block > 65536)
    throw InvalidArgument("ChannelPlayer: max_block is " + std::to_string(max_block) + "; allowed: 1 … 65536");
  players_.reserve(channels.size());
  for (const Channel& ch : channels) {
    PlayerConfig c = config;
    c.response = ch.response;
    players_.push_back(
        std::make_unique<Player>(c, ch.surface ? PlayerMap::from_surface(*ch.surface) : std::unique_ptr<const PlayerMap>()));
    offsets_.push_back(ch.offset.value());
  }
  scratch_.assign(max_block_ * channels.size(), 0.0f);
  scratch_position_.assign(max_block_, 0.0f);
}

ChannelPlayer::~ChannelPlayer() { stop_driver(); }

bool ChannelPlayer::push(const FingerSample& s) {
  // One producer: the space seen here can only grow before the pushes below.
  for (const auto& p : players_)
    if (p->event_space() == 0) return false;
  for (std::size_t c = 0; c < players_.size(); ++c) {
    FingerSample shifted = s;
    shifted.x_mm += offsets_[c];
    players_[c]->push(shifted);
  }
  return true;
}

void ChannelPlayer::set_maps(std::vector<std::unique_ptr<const PlayerMap>> maps, std::span<const Millimetres> offsets) {
  const std::size_t n = players_.size();
  if (maps.size() != n)
    throw InvalidArgument("ChannelPlayer::set_maps: " + std::to_string(maps.size()) + " maps for " + std::to_string(n) +
                          " channels; give one per channel");
  for (std::size_t c = 0; c < n; ++c)
    if (!maps[c])
      throw InvalidArgument("ChannelPlayer::set_maps: channel " + std::to_string(c) +
                            "'s map is null; a channel at rest is given a silent map");
  if (!offsets.empty()) check_offsets(offsets);
  // Checked first, so a refusal swaps nothing; then back to back, so the
  // real-time thread sees the maps within one block of each other.
  for (std::size_t c = 0; c < n; ++c) players_[c]->set_map(std::move(maps[c]));
  for (std::size_t c = 0; c < offsets.size(); ++c) offsets_[c] = offsets[c].value();
}

void ChannelPlayer::set_offsets(std::span<const Millimetres> offsets) {
  check_offsets(offsets);
  for (std::size_t c = 0; c < offsets.size(); ++c) offsets_[c] = offsets[c].value();
}

void ChannelPlayer::check_offsets(std::span<const Millimetres> offsets) const {
  if (offsets.size() != players_.size())
    throw InvalidArgument("ChannelPlayer: " + std::to_string(offsets.size()) + " offsets for " + std::to_string(players_.size()) +
                          " channels; give one per channel");
  for (std::size_t c = 0; c < offsets.size(); ++c)
    if (!(std::abs(offsets[c].value()) <= actuator_offset_mm_max))
      throw InvalidArgument("ChannelPlayer: channel " + std::to_string(c) + "'s offset is " + detail::num(offsets[c].value()) +
                            " mm; allowed: −50 … 50 mm");
}

std::size_t ChannelPlayer::collect() {
  std::size_t n = 0;
  for (const auto& p : players_) n += p->collect();
  return n;
}

BlockInfo ChannelPlayer::process_planar(std::span<const std::span<float>> outs, std::span<float> position_mm) noexcept {
  // Real-time: one Player::process per channel, then arithmetic on caller memory.
  const std::size_t n = std::min(outs.size(), players_.size());
  BlockInfo info;
  for (std::size_t c = 0; c < n; ++c) {
    const BlockInfo ci =
        players_[c]->process(outs[c], c == 0 && position_mm.size() == outs[0].size() ? position_mm : std::span<float>{});
    if (c == 0) info = ci;
    info.peak = std::max(info.peak, ci.peak);
    info.crossfading = info.crossfading || ci.crossfading;
  }
  if (n > 0) {
    info.position_mm -= offsets_[0];
    if (position_mm.size() == outs[0].size()) {
      const auto offset = static_cast<float>(offsets_[0]);
      for (float& x : position_mm) x -= offset;
    }
    frames_ += outs[0].size();
    publish_samples(frames_);
  }
  return info;
}

BlockInfo ChannelPlayer::process(std::span<float> out, std::span<float> position_mm) noexcept {
  // Real-time: the scratch block was allocated at prepare; spans are views.
  const std::size_t n = players_.size();
  const std::size_t frames = out.size() / n;
  const bool positions = position_mm.size() == frames;
  std::span<float> planar[max_actuators];
  BlockInfo info;
  for (std::size_t done = 0; done < frames;) {
    const std::size_t m = std::min(max_block_, frames - done);
    for (std::size_t c = 0; c < n; ++c) planar[c] = std::span(scratch_).subspan(c * max_block_, m);
    const float peak = info.peak;
    info = process_planar(std::span<const std::span<float>>(planar, n),
                          positions ? position_mm.subspan(done, m) : std::span<float>{});
    info.peak = std::max(info.peak, peak);
    for (std::size_t i = 0; i < m; ++i)
      for (std::size_t c = 0; c < n; ++c) out[(done + i) * n + c] = planar[c][i];
    done += m;
  }
  return info;
}

std::vector<float> render_trace_channels(std::span<const Channel> channels, const PlayerConfig& config,
                                         std::span<const FingerSample> trace, std::size_t frames, std::vector<float>* positions,
                                         std::size_t block) {
  if (block == 0 || block > 65536)
    throw InvalidArgument("render_trace_channels: block is " + std::to_string(block) + "; allowed: 1 … 65536");
  ChannelPlayer player(config, channels, block);
  const std::size_t n = player.channels();
  std::vector<float> out(frames * n);
  if (positions) positions->assign(frames, 0.0f);
  std::size_t next = 0;
  for (std::size_t done = 0; done < frames;) {
    while (next < trace.size() && player.push(trace[next])) ++next;
    const std::size_t m = std::min(block, frames - done);
    player.process(std::span(out).subspan(done * n, m * n),
                   positions ? std::span(*positions).subspan(done, m) : std::span<float>{});
    done += m;
  }
  return out;
}

}  // namespace texel
