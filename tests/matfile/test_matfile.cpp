// texel_mat: round trips through libmatio in both versions, the documented
// map-selection rule, atomic writes, and hostile files rejected with one line
// naming the file and the variable.
#include <gtest/gtest.h>
#include <matio.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "../support/temp_dir.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"
#include "texel/matfile.hpp"

namespace fs = std::filesystem;
using namespace texel;
using namespace texel::mat;

namespace {

class MatFile : public ::testing::Test {
 protected:
  std::string path(const std::string& name) const { return tmp_.at(name); }
  texel::test_support::TempDir tmp_{"texel-matfile"};
  const fs::path& dir_ = tmp_.path;
};

std::vector<double> ramp(std::size_t n, double scale = 1.0) {
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = scale * static_cast<double>(i) / static_cast<double>(n);
  return v;
}

std::vector<double> positions(std::size_t n, double step) {
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<double>(i) * step;
  return v;
}

/// Writes one variable with libmatio directly (for classes texel_mat never writes).
void write_raw(const std::string& file, matvar_t* var, mat_ft version = MAT_FT_MAT5) {
  mat_t* m = Mat_CreateVer(file.c_str(), nullptr, version);
  ASSERT_NE(m, nullptr);
  ASSERT_NE(var, nullptr);
  EXPECT_EQ(Mat_VarWrite(m, var, MAT_COMPRESSION_NONE), 0);
  Mat_VarFree(var);
  Mat_Close(m);
}

/// Expects read_map to throw FormatError whose one-line message names the
/// file and contains `fragment`.
void expect_rejected(const std::string& file, const std::string& fragment) {
  try {
    (void)read_map(file);
    FAIL() << file << " was accepted; expected: " << fragment;
  } catch (const FormatError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(file), std::string::npos) << m;
    EXPECT_NE(m.find(fragment), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

// A level-5 file built byte by byte: header + one uncompressed miMATRIX of
// class double named `map` with the given dimensions and `data_bytes` of real data.
std::string v5_bytes(const std::vector<std::int32_t>& dims, std::size_t data_bytes, std::uint32_t data_tag_bytes) {
  std::string out(116, ' ');
  std::memcpy(out.data(), "MATLAB 5.0 MAT-file, hand-made hostile file", 43);
  out.append(8, '\0');        // subsystem offset
  out.append("\x00\x01", 2);  // version 0x0100, little-endian
  out.append("IM", 2);
  auto u32 = [](std::string& s, std::uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); };
  std::string body;
  u32(body, 6), u32(body, 8), u32(body, 6), u32(body, 0);  // array flags: mxDOUBLE_CLASS
  u32(body, 5), u32(body, static_cast<std::uint32_t>(4 * dims.size()));
  for (auto d : dims) u32(body, static_cast<std::uint32_t>(d));
  if (dims.size() % 2) u32(body, 0);
  u32(body, (3u << 16) | 1u), body.append("map\0", 4);  // name "map", small element
  u32(body, 9), u32(body, data_tag_bytes);              // miDOUBLE real part
  body.append(data_bytes, '\0');
  u32(out, 14), u32(out, static_cast<std::uint32_t>(body.size()));
  return out + body;
}

void write_bytes(const std::string& file, const std::string& bytes) { std::ofstream(file, std::ios::binary) << bytes; }

}  // namespace

// --- round trips ------------------------------------------------------------------

TEST_F(MatFile, MapRoundTripsExactlyInBothVersions) {
  const std::vector<double> a = ramp(1000);
  for (MatVersion v : {MatVersion::v5, MatVersion::v73}) {
    for (bool compress : {true, false}) {
      const std::string f = path(std::string(v == MatVersion::v5 ? "v5" : "v73") + (compress ? "z" : "") + ".mat");
      write_mat(f, {{"amplitude", Matrix::column(a)}, {"position_mm", Matrix::column(positions(1000, 0.0053))}},
                {.version = v, .compress = compress});
      const MapData m = read_map(f);
      EXPECT_EQ(m.variable, "amplitude");
      EXPECT_EQ(m.amplitude, a);
      ASSERT_TRUE(m.spacing_mm.has_value());
      EXPECT_NEAR(*m.spacing_mm, 0.0053, 1e-15);
      EXPECT_EQ(m.position_mm.size(), 1000u);
    }
  }
}

TEST_F(MatFile, ColumnMajorShapesAndClassesAreWhatMatlabSees) {
  const std::string f = path("shapes.mat");
  // A 3×2 table: column 0 = {1,2,3}, column 1 = {10,20,30}.
  Struct s;
  s.add("k", Matrix::scalar(2.5)).add("name", Text{"tpad µ"}).add("labels", StringColumn{{"a", "bc", ""}});
  write_mat(f,
            {{"table", Matrix{3, 2, {1, 2, 3, 10, 20, 30}}}, {"row", Matrix{1, 4, {1, 2, 3, 4}}}, {"p", s}, {"doc", Text{"{}"}}});
  const auto vars = list_variables(f);
  ASSERT_EQ(vars.size(), 4u);
  EXPECT_EQ(vars[0], "table double 3x2");
  EXPECT_EQ(vars[1], "row double 1x4");
  EXPECT_EQ(vars[2], "p struct 1x1");
  EXPECT_EQ(vars[3], "doc char 1x2");
  // Element (r = 0, c = 1) must be 10 to MATLAB: read it back with matio.
  mat_t* m = Mat_Open(f.c_str(), MAT_ACC_RDONLY);
  ASSERT_NE(m, nullptr);
  matvar_t* t = Mat_VarRead(m, "table");
  ASSERT_NE(t, nullptr);
  const auto* d = static_cast<const double*>(t->data);
  EXPECT_EQ(d[0 + 1 * 3], 10.0);
  EXPECT_EQ(d[2 + 0 * 3], 3.0);
  Mat_VarFree(t);
  matvar_t* p = Mat_VarRead(m, "p");
  ASSERT_NE(p, nullptr);
  matvar_t* name = Mat_VarGetStructFieldByName(p, "name", 0);
  ASSERT_NE(name, nullptr);
  EXPECT_EQ(name->class_type, MAT_C_CHAR);
  EXPECT_EQ(name->dims[1], 6u);  // "tpad µ": 6 UTF-16 code units
  EXPECT_EQ(static_cast<const std::uint16_t*>(name->data)[5], 0xB5);
  matvar_t* labels = Mat_VarGetStructFieldByName(p, "labels", 0);
  ASSERT_NE(labels, nullptr);
  EXPECT_EQ(labels->class_type, MAT_C_CELL);
  EXPECT_EQ(labels->dims[0], 3u);
  Mat_VarFree(p);
  Mat_Close(m);
}

TEST_F(MatFile, SameInputGivesSameV5Bytes) {
  write_mat(path("a.mat"), {{"amplitude", Matrix::column(ramp(100))}});
  write_mat(path("b.mat"), {{"amplitude", Matrix::column(ramp(100))}});
  EXPECT_EQ(read_file(path("a.mat")), read_file(path("b.mat")));
}

// --- the selection rule ----------------------------------------------------------

TEST_F(MatFile, MapIsAmplitudeThenMapThenTheOnlyVector) {
  write_mat(path("map.mat"), {{"x", Matrix::column(ramp(10))}, {"map", Matrix::column(ramp(20))}});
  EXPECT_EQ(read_map(path("map.mat")).variable, "map");
  write_mat(path("amp.mat"),
            {{"map", Matrix::column(ramp(20))}, {"amplitude", Matrix::column(ramp(30))}, {"spacing_mm", Matrix::scalar(0.1)}});
  const MapData a = read_map(path("amp.mat"));
  EXPECT_EQ(a.variable, "amplitude");
  EXPECT_EQ(a.amplitude.size(), 30u);
  EXPECT_EQ(a.spacing_mm, 0.1);
  EXPECT_TRUE(a.position_mm.empty());
  // The only real numeric vector, whatever its name; a row works too.
  write_mat(path("only.mat"), {{"signal", Matrix{1, 5, ramp(5)}}, {"note", Text{"x"}}, {"k", Matrix::scalar(3)}});
  const MapData o = read_map(path("only.mat"));
  EXPECT_EQ(o.variable, "signal");
  EXPECT_FALSE(o.spacing_mm.has_value());
  write_mat(path("two.mat"), {{"a", Matrix::column(ramp(5))}, {"b", Matrix::column(ramp(6))}});
  expect_rejected(path("two.mat"), "2 real numeric vectors (a, b)");
  write_mat(path("none.mat"), {{"note", Text{"x"}}});
  expect_rejected(path("none.mat"), "no real numeric vector");
}

TEST_F(MatFile, IntegerAndSingleMapsAreReadAsTheirValues) {
  std::vector<std::int16_t> v{-3, 0, 7, 32767};
  std::size_t dims[2] = {4, 1};
  write_raw(path("i16.mat"), Mat_VarCreate("amplitude", MAT_C_INT16, MAT_T_INT16, 2, dims, v.data(), 0));
  EXPECT_EQ(read_map(path("i16.mat")).amplitude, (std::vector<double>{-3, 0, 7, 32767}));
  std::vector<float> f{0.25f, 0.5f, 0.75f, 1.0f};
  write_raw(path("single.mat"), Mat_VarCreate("amplitude", MAT_C_SINGLE, MAT_T_SINGLE, 2, dims, f.data(), 0), MAT_FT_MAT73);
  EXPECT_EQ(read_map(path("single.mat")).amplitude, (std::vector<double>{0.25, 0.5, 0.75, 1.0}));
}

TEST_F(MatFile, PositionsAndSpacingAreChecked) {
  std::vector<double> x = positions(10, 0.5);
  write_mat(path("len.mat"), {{"amplitude", Matrix::column(ramp(10))}, {"position_mm", Matrix::column(positions(9, 0.5))}});
  expect_rejected(path("len.mat"), "'position_mm' has 9 elements, 'amplitude' has 10");
  x[4] += 0.2;
  write_mat(path("uneven.mat"), {{"amplitude", Matrix::column(ramp(10))}, {"position_mm", Matrix::column(x)}});
  expect_rejected(path("uneven.mat"), "not uniformly sampled at element 5");
  std::reverse(x.begin(), x.end());
  write_mat(path("down.mat"), {{"amplitude", Matrix::column(ramp(10))}, {"position_mm", Matrix::column(x)}});
  expect_rejected(path("down.mat"), "must increase");
  write_mat(path("disagree.mat"), {{"amplitude", Matrix::column(ramp(10))},
                                   {"position_mm", Matrix::column(positions(10, 0.5))},
                                   {"spacing_mm", Matrix::scalar(0.25)}});
  expect_rejected(path("disagree.mat"), "'spacing_mm' is 0.25 mm");
  write_mat(path("neg.mat"), {{"amplitude", Matrix::column(ramp(10))}, {"spacing_mm", Matrix::scalar(-1)}});
  expect_rejected(path("neg.mat"), "it must be > 0 mm");
  write_mat(path("vec.mat"), {{"amplitude", Matrix::column(ramp(10))}, {"spacing_mm", Matrix::column(ramp(2))}});
  expect_rejected(path("vec.mat"), "it must be a scalar");
}

// --- hostile files -----------------------------------------------------------------

TEST_F(MatFile, WrongClassesAreRejectedNamingTheVariable) {
  std::size_t dims[2] = {4, 1};
  double re[4] = {0, 1, 0, 1}, im[4] = {1, 1, 1, 1};
  mat_complex_split_t z{re, im};
  write_raw(path("complex.mat"), Mat_VarCreate("amplitude", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, &z, MAT_F_COMPLEX));
  expect_rejected(path("complex.mat"), "variable 'amplitude' is complex");

  mat_uint32_t ir[2] = {0, 2}, jc[2] = {0, 2};
  double sv[2] = {0.5, 0.25};
  mat_sparse_t sp{};
  sp.nzmax = 2, sp.ir = ir, sp.nir = 2, sp.jc = jc, sp.njc = 2, sp.ndata = 2, sp.data = sv;
  write_raw(path("sparse.mat"), Mat_VarCreate("amplitude", MAT_C_SPARSE, MAT_T_DOUBLE, 2, dims, &sp, 0));
  expect_rejected(path("sparse.mat"), "variable 'amplitude' is sparse");

  matvar_t* cell = Mat_VarCreate("amplitude", MAT_C_CELL, MAT_T_CELL, 2, dims, nullptr, 0);
  write_raw(path("cell.mat"), cell);
  expect_rejected(path("cell.mat"), "variable 'amplitude' is of class cell");

  write_mat(path("char.mat"), {{"map", Text{"0.1 0.2"}}});
  expect_rejected(path("char.mat"), "variable 'map' is of class char");
  Struct s;
  s.add("a", Matrix::column(ramp(3)));
  write_mat(path("struct.mat"), {{"amplitude", s}});
  expect_rejected(path("struct.mat"), "variable 'amplitude' is of class struct");

  std::uint8_t b[4] = {0, 1, 1, 0};
  write_raw(path("logical.mat"), Mat_VarCreate("amplitude", MAT_C_UINT8, MAT_T_UINT8, 2, dims, b, MAT_F_LOGICAL));
  expect_rejected(path("logical.mat"), "variable 'amplitude' is logical");

  write_mat(path("matrix.mat"), {{"amplitude", Matrix{2, 3, ramp(6)}}});
  expect_rejected(path("matrix.mat"), "variable 'amplitude' is 2x3; a map must be a vector");
  std::size_t dims3[3] = {2, 2, 2};
  std::vector<double> cube = ramp(8);
  write_raw(path("cube.mat"), Mat_VarCreate("amplitude", MAT_C_DOUBLE, MAT_T_DOUBLE, 3, dims3, cube.data(), 0), MAT_FT_MAT73);
  expect_rejected(path("cube.mat"), "is 2x2x2");

  std::vector<double> nan = ramp(4);
  nan[2] = std::numeric_limits<double>::quiet_NaN();
  write_mat(path("nan.mat"), {{"amplitude", Matrix::column(nan)}});
  expect_rejected(path("nan.mat"), "non-finite value at element 3");
  write_mat(path("empty.mat"), {{"amplitude", Matrix{0, 0, {}}}});
  expect_rejected(path("empty.mat"), "variable 'amplitude' is empty");
}

TEST_F(MatFile, HugeDeclaredDimensionsAreRejectedBeforeAllocating) {
  // 2^31-1 squared elements in a file of a few hundred bytes: over the cap.
  write_bytes(path("huge.mat"), v5_bytes({0x7FFFFFFF, 0x7FFFFFFF}, 8, 8));
  expect_rejected(path("huge.mat"), "more than the 134217728 elements allowed");
  // Three dimensions whose product overflows 64 bits.
  write_bytes(path("overflow.mat"), v5_bytes({0x7FFFFFFF, 0x7FFFFFFF, 0x7FFFFFFF}, 8, 8));
  expect_rejected(path("overflow.mat"), "elements allowed");
  // Under the cap, but far more elements than the uncompressed file has bytes.
  write_bytes(path("liar.mat"), v5_bytes({100000000, 1}, 8, 800000000));
  expect_rejected(path("liar.mat"), "but the file has only");
  // A caller's smaller cap applies too.
  write_mat(path("ok.mat"), {{"amplitude", Matrix::column(ramp(100))}});
  EXPECT_THROW((void)read_map(path("ok.mat"), {.max_elements = 50}), FormatError);
  EXPECT_EQ(read_map(path("ok.mat"), {.max_elements = 100}).amplitude.size(), 100u);
  // The hand-made format itself is right: a small honest file reads.
  write_bytes(path("honest.mat"), v5_bytes({2, 1}, 16, 16));
  EXPECT_EQ(read_map(path("honest.mat")).amplitude, (std::vector<double>{0, 0}));
}

// Findings of fuzz_mat: libmatio allocates by the member counts declared in
// a variable's headers while listing a file, so those are checked first
// (matfile.cpp, "v5 pre-check").
TEST_F(MatFile, DeclaredMembersMustFitTheFile) {
  // A cell declaring 2^30 members in a 48-byte file (libmatio: 8 GiB of pointers).
  std::string bytes(116, ' ');
  std::memcpy(bytes.data(), "MATLAB 5.0 MAT-file, hand-made hostile file", 43);
  bytes.append(8, '\0');
  bytes.append("\x00\x01", 2);
  bytes.append("IM", 2);
  auto u32 = [](std::string& s, std::uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); };
  std::string body;
  u32(body, 6), u32(body, 8), u32(body, 1), u32(body, 0);  // array flags: mxCELL_CLASS
  u32(body, 5), u32(body, 8), u32(body, 1u << 30), u32(body, 1);
  u32(body, (1u << 16) | 1u), body.append("c\0\0\0", 4);
  u32(bytes, 14), u32(bytes, static_cast<std::uint32_t>(body.size()));
  write_bytes(path("cell.mat"), bytes + body);
  expect_rejected(path("cell.mat"), "is corrupt: a cell declares 1073741824 members in 0 bytes");
  // The fuzzer's crasher: Texel's own map file with three bytes changed
  // inside its compressed elements (libmatio asked for 1.6 GB).
  const std::string crash = path("crash.mat");
  fs::copy_file(std::string(TEXEL_TEST_SOURCE_DIR) + "/tests/fuzz/corpus/fuzz_mat/crash-corrupt-compressed-struct.mat", crash);
  expect_rejected(crash, "is corrupt: a matrix is truncated, or its compressed stream is corrupt");
  // No v5/v7.3 marker at bytes 124-127: libmatio would fall back to v4 and
  // malloc a name length from the file (1.7 GB for the fuzzer's 972 bytes).
  const std::string v4 = path("v4.mat");
  fs::copy_file(std::string(TEXEL_TEST_SOURCE_DIR) + "/tests/fuzz/corpus/fuzz_mat/crash-v4-fallback.mat", v4);
  expect_rejected(v4, "is not a MATLAB v5/v7.3 .mat file (no version and byte-order mark at bytes 124-127)");
  // Texel's own files, compressed or not, with structs and cells, still read.
  Struct s;
  s.add("names", StringColumn{{"a", "bc", ""}}).add("m", Matrix::column(ramp(3)));
  for (bool compress : {true, false}) {
    write_mat(path("ok.mat"), {{"amplitude", Matrix::column(ramp(5))}, {"texel", s}}, {.compress = compress});
    EXPECT_EQ(read_map(path("ok.mat")).amplitude.size(), 5u);
  }
}

TEST_F(MatFile, TruncatedAndForeignFilesAreRejected) {
  write_mat(path("full.mat"), {{"amplitude", Matrix::column(ramp(5000))}}, {.compress = false});
  const std::string bytes = read_file(path("full.mat"));
  for (std::size_t keep :
       {std::size_t{0}, std::size_t{60}, std::size_t{128}, std::size_t{200}, bytes.size() / 2, bytes.size() - 1}) {
    const std::string f = path("cut" + std::to_string(keep) + ".mat");
    write_bytes(f, bytes.substr(0, keep));
    EXPECT_THROW((void)read_map(f), FormatError) << "kept " << keep << " of " << bytes.size() << " bytes";
  }
  write_mat(path("fullz.mat"), {{"amplitude", Matrix::column(ramp(5000))}});
  const std::string z = read_file(path("fullz.mat"));
  write_bytes(path("cutz.mat"), z.substr(0, z.size() / 2));
  EXPECT_THROW((void)read_map(path("cutz.mat")), FormatError);
  write_mat(path("v73.mat"), {{"amplitude", Matrix::column(ramp(5000))}}, {.version = MatVersion::v73});
  const std::string h = read_file(path("v73.mat"));
  write_bytes(path("cut73.mat"), h.substr(0, h.size() / 2));
  EXPECT_THROW((void)read_map(path("cut73.mat")), FormatError);

  write_bytes(path("text.mat"), std::string(300, 'x'));
  expect_rejected(path("text.mat"), "is not a MATLAB");
  EXPECT_THROW((void)read_map(path("missing.mat")), IoError);
  EXPECT_THROW((void)read_map(dir_.string()), IoError);
}

// --- writing -----------------------------------------------------------------------

TEST_F(MatFile, BadWritesLeaveNoFileBehind) {
  EXPECT_THROW(write_mat(path("bad.mat"), {{"1x", Matrix::scalar(1)}}), InvalidArgument);
  EXPECT_THROW(write_mat(path("bad.mat"), {{"a", Matrix::scalar(1)}, {"a", Matrix::scalar(2)}}), InvalidArgument);
  EXPECT_THROW(write_mat(path("bad.mat"), {{"a", Matrix{2, 2, {1, 2, 3}}}}), InvalidArgument);
  Struct s;
  s.add("ok", Matrix::scalar(1)).add("not ok", Matrix::scalar(2));
  EXPECT_THROW(write_mat(path("bad.mat"), {{"p", s}}), InvalidArgument);
  EXPECT_THROW(write_mat(path("no/such/dir/x.mat"), {{"a", Matrix::scalar(1)}}), IoError);
  EXPECT_TRUE(fs::is_empty(dir_)) << "a failed write left a file or temporary behind";
  // A failed rewrite keeps the old file.
  write_mat(path("keep.mat"), {{"amplitude", Matrix::column(ramp(10))}});
  EXPECT_THROW(write_mat(path("keep.mat"), {{"a", Matrix{2, 2, {1}}}}), InvalidArgument);
  EXPECT_EQ(read_map(path("keep.mat")).amplitude, ramp(10));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

TEST(MatVersionOption, ParsesTheDocumentedSpellings) {
  EXPECT_EQ(parse_mat_version("5"), MatVersion::v5);
  EXPECT_EQ(parse_mat_version("7"), MatVersion::v5);
  EXPECT_EQ(parse_mat_version("7.3"), MatVersion::v73);
  EXPECT_EQ(parse_mat_version("v7.3"), MatVersion::v73);
  EXPECT_THROW(parse_mat_version("6"), InvalidArgument);
}
