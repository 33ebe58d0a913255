// Multi-channel rendering: the document's texture per channel
// (texel/multichannel.hpp, docs/rendering.md).
#include "texel/multichannel.hpp"

#include <algorithm>

#include "texel/detail/format.hpp"
#include "texel/document.hpp"
#include "texel/error.hpp"
#include "texel/random.hpp"

namespace texel {

std::string_view to_string(ChannelMode m) { return m == ChannelMode::simultaneous ? "simultaneous" : "sequential"; }

ChannelMode parse_channel_mode(std::string_view text, std::string_view field) {
  if (text == "sequential") return ChannelMode::sequential;
  if (text == "simultaneous") return ChannelMode::simultaneous;
  throw InvalidArgument(std::string(field) + " is '" + std::string(text) + "'; allowed: sequential, simultaneous");
}

void validate(const ChannelPlayback& playback, std::size_t channels) {
  if (!playback.channel) return;
  if (playback.mode == ChannelMode::simultaneous)
    throw InvalidArgument("playback.channel is " + std::to_string(*playback.channel) +
                          "; allowed only with mode sequential (simultaneous plays every channel)");
  if (*playback.channel >= channels)
    throw InvalidArgument("playback.channel is " + std::to_string(*playback.channel) + "; allowed: 0 … " +
                          std::to_string(channels - 1) + " (the device has " + std::to_string(channels) + " channels)");
}

std::uint64_t channel_seed(std::uint64_t seed, std::size_t channel) {
  return CounterRng(seed, Stream::channel).bits(static_cast<std::uint64_t>(channel));
}

ChannelPlayback playback_of(const Document& doc) { return doc.playback ? *doc.playback : ChannelPlayback{}; }

std::vector<Channel> prepare_channels(const Document& doc) {
  if (doc.surface2d) throw InvalidArgument("a 2-D document (surface2d) has no multi-channel playback; it plays on one channel");
  const std::size_t n = doc.device.channels();
  const ChannelPlayback playback = playback_of(doc);
  validate(playback, n);
  std::vector<Channel> channels(n);
  for (std::size_t c = 0; c < n; ++c) {
    if (c < doc.device.actuators.size()) {
      channels[c].name = doc.device.actuators[c].name;
      channels[c].offset = doc.device.actuators[c].offset;
    }
    channels[c].response = doc.device.channel_response(c);
  }
  if (playback.mode == ChannelMode::sequential) {
    // One map, shared: every channel reads the document's own bytes.
    const auto surface = std::make_shared<const Surface>(prepare_surface(doc));
    for (std::size_t c = 0; c < n; ++c)
      if (!playback.channel || *playback.channel == c) channels[c].surface = surface;
    return channels;
  }
  for (std::size_t i = 0; i < doc.regions.size(); ++i)
    if (doc.regions[i].reference)
      throw InvalidArgument("playback.mode is 'simultaneous', but region " + std::to_string(i) +
                            " holds a reference texture, which has no texels to draw per channel; allowed: Texel regions "
                            "only (or mode sequential)");
  for (std::size_t c = 0; c < n; ++c) {
    Document channel_doc = doc;
    channel_doc.playback.reset();
    for (auto& r : channel_doc.regions) r.texel.seed = channel_seed(r.texel.seed, c);
    channels[c].surface = std::make_shared<const Surface>(prepare_surface(channel_doc));
  }
  return channels;
}

std::vector<double> channel_texel_frequencies(const Channel& channel) {
  std::vector<double> out;
  if (!channel.surface) return out;
  for (const auto& region : channel.surface->regions()) {
    const auto* texels = dynamic_cast<const TexelTexture*>(region.texture.get());
    if (!texels) continue;
    out.reserve(out.size() + texels->texel_count());
    texels->for_each_texels([&](std::size_t, std::span<const Texel> run) {
      for (const Texel& t : run) out.push_back(t.frequency.value());
    });
  }
  return out;
}

void render_channels(std::span<const Channel> channels, std::int64_t first, std::span<double> out) {
  const std::size_t n = channels.size();
  if (n == 0) throw InvalidArgument("render_channels: no channels");
  if (out.size() % n != 0)
    throw InvalidArgument("render_channels: out holds " + std::to_string(out.size()) + " values, not a multiple of " +
                          std::to_string(n) + " channels");
  const std::size_t frames = out.size() / n;
  std::vector<double> one(frames);
  for (std::size_t c = 0; c < n; ++c) {
    if (channels[c].surface)
      channels[c].surface->render(first, one);
    else
      std::fill(one.begin(), one.end(), 0.0);
    for (std::size_t i = 0; i < frames; ++i) out[i * n + c] = one[i];
  }
}

}  // namespace texel
