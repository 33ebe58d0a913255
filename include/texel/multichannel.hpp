// Multi-channel rendering (docs/rendering.md): a device whose profile
// declares N actuators (DeviceProfile::actuators) plays a 1-D document on N
// channels, in one of two ways:
//  - sequential: today's chain of texels, the one texture, on every channel
//    (each actuator reads it where it touches the surface: finger position +
//    its offset) or on one channel (the others at rest);
//  - simultaneous: at every instant K = N texels sound at once, one per
//    actuator. Channel c plays its own chain of single-frequency texels of
//    the texture's texel length, its frequencies drawn from the same
//    lognormal (Central Pitch, Irregularity, band, quantization) with its own
//    counter-based stream: the texture's seed mixed with the channel index
//    (channel_seed), so channel c's texel k is a pure function of (seed, c, k)
//    exactly as a 1-D texture's texel k is of (seed, k), and any channel or
//    window renders alone with the same bytes.
// The trade-off: a simultaneous channel is a whole 1-D texture of its own
// (same coarse profile and strengths, its own fine draws), so everything a
// texture does (regions, random access, the player's texel evaluation) holds
// per channel unchanged, at the cost of N prepared textures.
//
// A document selects the playback with "playback" (document version 6,
// docs/format.md); documents without it play sequential on every channel,
// which on a one-channel device is the one map they always rendered.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "texel/device.hpp"
#include "texel/surface.hpp"
#include "texel/units.hpp"

namespace texel {

struct Document;

enum class ChannelMode {
  sequential,    ///< the texture's one chain of texels (on every channel, or on one)
  simultaneous,  ///< one chain per channel, drawn from the same distribution
};
std::string_view to_string(ChannelMode m);
/// "sequential" / "simultaneous"; throws InvalidArgument naming `field`.
ChannelMode parse_channel_mode(std::string_view text, std::string_view field = "playback.mode");

/// How a document plays on the device's channels (JSON "playback", version 6).
struct ChannelPlayback {
  ChannelMode mode = ChannelMode::sequential;
  /// Sequential only: the one channel that plays (0-based, < the device's
  /// channels); none = every channel. Simultaneous plays every channel.
  std::optional<std::size_t> channel;
};
/// Throws InvalidArgument naming the field, the value and what is allowed,
/// for a device of `channels` channels.
void validate(const ChannelPlayback& playback, std::size_t channels);

/// The seed channel c's texels are drawn with in simultaneous playback: 64
/// bits of the counter-based stream Stream::channel of `seed` at counter c
/// (texel/random.hpp), so channels are decorrelated from one another and from
/// the texture's own draws.
std::uint64_t channel_seed(std::uint64_t seed, std::size_t channel);

/// What one channel (actuator) of a document plays.
struct Channel {
  std::string name;                        ///< the actuator's name ("" on a one-channel device)
  std::shared_ptr<const Surface> surface;  ///< the map it reads; null = at rest (sequential on another channel)
  Millimetres offset{0.0};                 ///< reads the surface at finger position + offset
  FrequencyResponse response;              ///< its actuator's response, else the device's
};

/// Prepares every channel of a 1-D document (prepare: validates and
/// allocates). Sequential channels share one Surface, the document's
/// (prepare_surface(doc), bit for bit); simultaneous channel c is the
/// document with every Texel region's seed replaced by channel_seed(seed, c).
/// Throws InvalidArgument for a 2-D document, a simultaneous document with a
/// reference region (a reference has no texels to draw), or an invalid
/// playback.
std::vector<Channel> prepare_channels(const Document& doc);

/// The document's playback: doc.playback, or sequential on every channel.
ChannelPlayback playback_of(const Document& doc);

/// Every texel frequency (cycles/mm) channel `channel` plays, region by
/// region in order (Texel regions only; empty for a channel at rest).
std::vector<double> channel_texel_frequencies(const Channel& channel);

/// The channels' maps on the device grid, interleaved: out[i·N + c] is
/// channel c's amplitude at grid sample first + i (0 for a channel at rest).
/// Any window gives the same values. out.size() must be a multiple of N.
void render_channels(std::span<const Channel> channels, std::int64_t first, std::span<double> out);

}  // namespace texel
