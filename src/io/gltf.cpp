// A glTF 2.0 asset carrying a Texel texture as an MPEG haptic material
// (texel/interchange.hpp; docs/interchange.md "glTF").
//
// The asset is the smallest one a scene viewer and a haptic renderer can both
// use: one quad the size of the display, its base colour the amplitude map
// (so a plain glTF viewer shows the texture), and the MPEG scene-description
// extensions (KhronosGroup/glTF extensions/2.0/Vendor/MPEG_haptic,
// MPEG_haptic_material): the haptic object points through MPEG_media at the
// exported .hjif, and the haptic material lists the map as a High_Resolution
// texture plus a Reference texture to that object. The PNG is written here
// (stored deflate blocks): lossless, 16-bit, no image library.
#include <array>
#include <cmath>
#include <cstring>

#include <nlohmann/json.hpp>

#include "texel/error.hpp"
#include "texel/interchange.hpp"
#include "texel/surface.hpp"

namespace texel::gltf {
namespace {

using ojson = nlohmann::ordered_json;

void put32be(std::vector<std::byte>& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<std::byte>((v >> s) & 0xFF));
}
void put32le(std::vector<std::byte>& out, std::uint32_t v) {
  for (int s = 0; s <= 24; s += 8) out.push_back(static_cast<std::byte>((v >> s) & 0xFF));
}

std::uint32_t crc32(const std::byte* data, std::size_t n, std::uint32_t crc = 0) {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  crc = ~crc;
  for (std::size_t i = 0; i < n; ++i) crc = table[(crc ^ std::to_integer<std::uint32_t>(data[i])) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

void chunk(std::vector<std::byte>& png, const char* type, const std::vector<std::byte>& data) {
  put32be(png, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = png.size();
  for (int i = 0; i < 4; ++i) png.push_back(static_cast<std::byte>(type[i]));
  png.insert(png.end(), data.begin(), data.end());
  put32be(png, crc32(png.data() + start, png.size() - start));
}

std::string base64(std::span<const std::byte> in) {
  static constexpr char abc[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < in.size(); i += 3) {
    const std::uint32_t b0 = std::to_integer<std::uint32_t>(in[i]);
    const std::uint32_t b1 = i + 1 < in.size() ? std::to_integer<std::uint32_t>(in[i + 1]) : 0;
    const std::uint32_t b2 = i + 2 < in.size() ? std::to_integer<std::uint32_t>(in[i + 2]) : 0;
    const std::uint32_t v = (b0 << 16) | (b1 << 8) | b2;
    out += abc[(v >> 18) & 63];
    out += abc[(v >> 12) & 63];
    out += i + 1 < in.size() ? abc[(v >> 6) & 63] : '=';
    out += i + 2 < in.size() ? abc[v & 63] : '=';
  }
  return out;
}

template <typename T>
void append(std::vector<std::byte>& buf, const T& v) {
  const auto* p = reinterpret_cast<const std::byte*>(&v);
  buf.insert(buf.end(), p, p + sizeof v);  // glTF buffers are little-endian, as is every target Texel builds for
}
void pad4(std::vector<std::byte>& buf, std::byte fill = std::byte{0}) {
  while (buf.size() % 4) buf.push_back(fill);
}

}  // namespace

std::vector<std::byte> png_row16(std::span<const double> amplitudes) {
  if (amplitudes.empty() || amplitudes.size() > 0x7FFFFFFFu) throw InvalidArgument("a PNG row needs 1 … 2^31 − 1 samples");
  std::vector<std::byte> raw;
  raw.reserve(1 + amplitudes.size() * 2);
  raw.push_back(std::byte{0});  // filter: none
  for (double a : amplitudes) {
    const double c = std::isfinite(a) ? std::fmin(1.0, std::fmax(0.0, a)) : 0.0;
    const auto v = static_cast<std::uint16_t>(std::lround(c * 65535.0));
    raw.push_back(static_cast<std::byte>(v >> 8));
    raw.push_back(static_cast<std::byte>(v & 0xFF));
  }
  // zlib stream of stored blocks (RFC 1950/1951), Adler-32 at the end.
  std::vector<std::byte> z{std::byte{0x78}, std::byte{0x01}};
  for (std::size_t at = 0; at < raw.size() || at == 0; at += 65535) {
    const std::size_t len = std::min<std::size_t>(65535, raw.size() - at);
    const bool last = at + len >= raw.size();
    z.push_back(static_cast<std::byte>(last ? 1 : 0));
    z.push_back(static_cast<std::byte>(len & 0xFF));
    z.push_back(static_cast<std::byte>(len >> 8));
    z.push_back(static_cast<std::byte>(~len & 0xFF));
    z.push_back(static_cast<std::byte>((~len >> 8) & 0xFF));
    z.insert(z.end(), raw.begin() + static_cast<std::ptrdiff_t>(at), raw.begin() + static_cast<std::ptrdiff_t>(at + len));
    if (last) break;
  }
  std::uint32_t s1 = 1;
  std::uint32_t s2 = 0;
  for (std::byte b : raw) {
    s1 = (s1 + std::to_integer<std::uint32_t>(b)) % 65521;
    s2 = (s2 + s1) % 65521;
  }
  put32be(z, (s2 << 16) | s1);

  std::vector<std::byte> png;
  constexpr unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  for (unsigned char c : signature) png.push_back(static_cast<std::byte>(c));
  std::vector<std::byte> ihdr;
  put32be(ihdr, static_cast<std::uint32_t>(amplitudes.size()));
  put32be(ihdr, 1);
  constexpr unsigned char format[5] = {16, 0, 0, 0, 0};
  for (unsigned char c : format) ihdr.push_back(static_cast<std::byte>(c));  // 16-bit grey, deflate, no filter set, no interlace
  chunk(png, "IHDR", ihdr);
  chunk(png, "IDAT", z);
  chunk(png, "IEND", {});
  return png;
}

namespace {

/// The asset around an image: a quad of L × W metres whose texture
/// coordinates end at (u_end, v_end) of the image, the haptic object and
/// material (the Reference texture only when a .hjif is referenced).
std::vector<std::byte> assemble(const std::vector<std::byte>& png, float L, float W, float u_end, float v_end,
                                const std::string& node_name, const AssetOptions& o, Container container) {
  // Geometry: positions, normals, texture coordinates, indices (one quad).
  std::vector<std::byte> buf;
  const float pos[4][3] = {{0, 0, 0}, {L, 0, 0}, {L, W, 0}, {0, W, 0}};
  for (const auto& p : pos)
    for (float c : p) append(buf, c);
  const std::size_t normals_at = buf.size();
  for (int v = 0; v < 4; ++v)
    for (float c : {0.0f, 0.0f, 1.0f}) append(buf, c);
  const std::size_t uv_at = buf.size();
  const float uv[4][2] = {{0, v_end}, {u_end, v_end}, {u_end, 0}, {0, 0}};
  for (const auto& t : uv)
    for (float c : t) append(buf, c);
  const std::size_t index_at = buf.size();
  constexpr std::uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
  for (std::uint16_t i : indices) append(buf, i);
  const std::size_t geometry_bytes = buf.size();
  pad4(buf);
  const std::size_t image_at = buf.size();
  if (container == Container::glb) {
    buf.insert(buf.end(), png.begin(), png.end());
    pad4(buf);
  }

  ojson views = ojson::array();
  views.push_back({{"buffer", 0}, {"byteOffset", 0}, {"byteLength", uv_at}, {"byteStride", 12}, {"target", 34962}});
  views.push_back({{"buffer", 0}, {"byteOffset", uv_at}, {"byteLength", index_at - uv_at}, {"byteStride", 8}, {"target", 34962}});
  views.push_back({{"buffer", 0}, {"byteOffset", index_at}, {"byteLength", geometry_bytes - index_at}, {"target", 34963}});
  ojson image;
  if (container == Container::glb) {
    views.push_back({{"buffer", 0}, {"byteOffset", image_at}, {"byteLength", png.size()}});
    image = {{"name", "amplitude map"}, {"bufferView", 3}, {"mimeType", "image/png"}};
  } else {
    image = {{"name", "amplitude map"}, {"uri", "data:image/png;base64," + base64(png)}};
  }
  ojson accessors = ojson::array();
  accessors.push_back({{"bufferView", 0},
                       {"byteOffset", 0},
                       {"componentType", 5126},
                       {"count", 4},
                       {"type", "VEC3"},
                       {"min", {0.0, 0.0, 0.0}},
                       {"max", {L, W, 0.0}}});
  accessors.push_back({{"bufferView", 0}, {"byteOffset", normals_at}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}});
  accessors.push_back({{"bufferView", 1}, {"byteOffset", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC2"}});
  accessors.push_back({{"bufferView", 2}, {"byteOffset", 0}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}});

  ojson buffer{{"byteLength", container == Container::glb ? buf.size() : geometry_bytes}};
  if (container == Container::gltf)
    buffer["uri"] = "data:application/octet-stream;base64," + base64(std::span<const std::byte>(buf.data(), geometry_bytes));

  const std::string modality_key = o.modality == hjif::Modality::friction ? "friction" : "vibrotactileTexture";
  ojson textures = ojson::array({ojson{{"texture", {{"index", 0}}}, {"type", "High_Resolution"}}});
  if (!o.hjif_uri.empty()) textures.push_back(ojson{{"texture", {{"index", 0}}}, {"type", "Reference"}});
  ojson material{{"name", "Texel texture"}, {"haptic", 0}, {modality_key, std::move(textures)}};
  if (o.hjif_uri.empty()) material.erase("haptic");
  ojson root{
      {"asset",
       {{"version", "2.0"}, {"generator", o.hjif_uri.empty() ? "Texel (texel render --surface 2d)" : "Texel (texel export)"}}},
      {"extensionsUsed", {"MPEG_media", "MPEG_haptic", "MPEG_haptic_material"}},
      {"extensions",
       {{"MPEG_media",
         {{"media",
           ojson::array({ojson{{"name", "Texel texture"},
                               {"alternatives", ojson::array({ojson{{"uri", o.hjif_uri}, {"mimeType", "haptics/hjif"}}})}}})}}},
        {"MPEG_haptic", {{"hapticObjects", ojson::array({ojson{{"name", "Texel texture"}, {"mediaReference", {0}}}})}}},
        {"MPEG_haptic_material", {{"materials", ojson::array({std::move(material)})}}}}},
      {"scene", 0},
      {"scenes", ojson::array({ojson{{"name", "display"}, {"nodes", {0}}}})},
      {"nodes", ojson::array({ojson{{"name", node_name}, {"mesh", 0}}})},
      {"meshes",
       ojson::array({ojson{{"name", "display surface"},
                           {"primitives", ojson::array({ojson{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}}},
                                                              {"indices", 3},
                                                              {"material", 0}}})},
                           {"extensions", {{"MPEG_haptic_material", {{"hapticMaterialIndex", 0}}}}}}})},
      {"materials",
       ojson::array({ojson{
           {"name", "amplitude map"},
           {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0.0}, {"roughnessFactor", 1.0}}},
           {"doubleSided", true}}})},
      {"textures", ojson::array({ojson{{"sampler", 0}, {"source", 0}}})},
      {"samplers", ojson::array({ojson{{"magFilter", 9728}, {"minFilter", 9728}, {"wrapS", 33071}, {"wrapT", 33071}}})},
      {"images", ojson::array({std::move(image)})},
      {"accessors", std::move(accessors)},
      {"bufferViews", std::move(views)},
      {"buffers", ojson::array({std::move(buffer)})}};

  if (o.hjif_uri.empty()) {
    // A 2-D map without a haptic stream: the material alone.
    root["extensionsUsed"] = {"MPEG_haptic_material"};
    root["extensions"].erase("MPEG_media");
    root["extensions"].erase("MPEG_haptic");
  }
  std::string text = root.dump();
  if (container == Container::gltf) {
    text += "\n";
    const auto* p = reinterpret_cast<const std::byte*>(text.data());
    return {p, p + text.size()};
  }
  std::vector<std::byte> json_chunk(reinterpret_cast<const std::byte*>(text.data()),
                                    reinterpret_cast<const std::byte*>(text.data()) + text.size());
  pad4(json_chunk, std::byte{' '});
  std::vector<std::byte> out;
  put32le(out, 0x46546C67u);  // "glTF"
  put32le(out, 2);
  put32le(out, static_cast<std::uint32_t>(12 + 8 + json_chunk.size() + 8 + buf.size()));
  put32le(out, static_cast<std::uint32_t>(json_chunk.size()));
  put32le(out, 0x4E4F534Au);  // "JSON"
  out.insert(out.end(), json_chunk.begin(), json_chunk.end());
  put32le(out, static_cast<std::uint32_t>(buf.size()));
  put32le(out, 0x004E4942u);  // "BIN\0"
  out.insert(out.end(), buf.begin(), buf.end());
  return out;
}

}  // namespace

std::vector<std::byte> asset(const Document& doc, const AssetOptions& o, Container container) {
  if (!(std::isfinite(o.width_mm) && o.width_mm > 0.0)) throw FieldError("width", "must be a length > 0 mm");
  if (o.hjif_uri.empty()) throw FieldError("hjif_uri", "is empty; the asset references the exported .hjif by URI");
  const Surface surface = prepare_surface(doc);
  std::vector<double> map = surface.render();
  // The image is a power of two wide (WebGL 1 and mipmaps need it; the
  // validator notes anything else): the map's samples one per pixel from the
  // left, zeros after, and the quad's texture coordinates end at the map.
  std::size_t width = 1;
  while (width < map.size()) width *= 2;
  const float u_end = static_cast<float>(static_cast<double>(map.size()) / static_cast<double>(width));
  map.resize(width, 0.0);
  const std::vector<std::byte> png = png_row16(map);
  const float L = static_cast<float>(surface.grid().length().value() / 1000.0);  // metres
  const float W = static_cast<float>(o.width_mm / 1000.0);
  return assemble(png, L, W, u_end, 1.0f, doc.device.name, o, container);
}

std::vector<std::byte> asset_2d(const std::vector<std::byte>& png, double width_mm, double height_mm, const std::string& name,
                                const AssetOptions& o, Container container) {
  if (!(std::isfinite(width_mm) && width_mm > 0.0 && std::isfinite(height_mm) && height_mm > 0.0))
    throw FieldError("width", "and height must be lengths > 0 mm");
  return assemble(png, static_cast<float>(width_mm / 1000.0), static_cast<float>(height_mm / 1000.0), 1.0f, 1.0f, name, o,
                  container);
}

}  // namespace texel::gltf
