// File I/O (io.hpp): .npy and .csv round trips and parsing, atomic writes
// that never leave a temporary or partial file, output extensions.
#include <gtest/gtest.h>
#include <rapidcheck/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include "../support/expect.hpp"
#include "../support/temp_dir.hpp"
#include "texel/error.hpp"
#include "texel/io.hpp"

using namespace texel;
namespace fs = std::filesystem;

namespace {

using texel::test_support::TempDir;

std::string npy_with(const std::string& header_dict, const std::string& data) {
  std::string header = header_dict;
  const std::size_t unpadded = 10 + header.size() + 1;
  header.append((64 - unpadded % 64) % 64, ' ');
  header.push_back('\n');
  std::string out("\x93NUMPY\x01\x00", 8);
  out.push_back(static_cast<char>(header.size() & 0xFF));
  out.push_back(static_cast<char>(header.size() >> 8));
  return out + header + data;
}

template <class T>
std::string raw_bytes(std::initializer_list<T> values) {
  std::string s;
  for (T v : values) s.append(reinterpret_cast<const char*>(&v), sizeof v);
  return s;
}

std::string format_error_of(const std::function<void()>& f) { return test_support::message_of<FormatError>(f); }

}  // namespace

RC_GTEST_PROP(Npy, RoundTripIsBitExact, ()) {
  const auto words = *rc::gen::container<std::vector<std::uint64_t>>(rc::gen::arbitrary<std::uint64_t>());
  std::vector<double> v;
  for (auto w : words) {
    const double d = std::bit_cast<double>(w);
    v.push_back(std::isnan(d) ? 0.5 : d);
  }
  const std::string bytes = npy_bytes(v);
  RC_ASSERT(bytes.substr(0, 8) == std::string("\x93NUMPY\x01\x00", 8));
  const std::size_t header_len = static_cast<unsigned char>(bytes[8]) | (static_cast<unsigned char>(bytes[9]) << 8);
  RC_ASSERT((10 + header_len) % 64 == 0u);  // NEP 1 alignment
  RC_ASSERT(bytes[10 + header_len - 1] == '\n');
  RC_ASSERT(bytes.size() == 10 + header_len + 8 * v.size());
  const auto back = parse_npy(bytes, "x.npy");
  RC_ASSERT(back.size() == v.size());
  // Not `RC_ASSERT(v.empty() || memcmp(...))`: RC_ASSERT decomposes its
  // expression, which defeats || short-circuiting (memcmp on null pointers).
  if (!v.empty()) RC_ASSERT(std::memcmp(back.data(), v.data(), 8 * v.size()) == 0);
}

TEST(Npy, ReadsOtherDtypesAndColumnShapes) {
  auto f4 = parse_npy(
      npy_with("{'descr': '<f4', 'fortran_order': False, 'shape': (3,), }", raw_bytes<float>({0.5f, 1.0f, -2.0f})), "a");
  EXPECT_EQ(f4, (std::vector<double>{0.5, 1.0, -2.0}));
  auto u2 = parse_npy(
      npy_with("{'descr': '<u2', 'fortran_order': False, 'shape': (2, 1), }", raw_bytes<std::uint16_t>({0, 65535})), "b");
  EXPECT_EQ(u2, (std::vector<double>{0.0, 1.0}));
  auto i2 = parse_npy(
      npy_with("{'descr': '<i2', 'fortran_order': False, 'shape': (1, 2), }", raw_bytes<std::int16_t>({-32768, 16384})), "c");
  EXPECT_EQ(i2, (std::vector<double>{-1.0, 0.5}));
}

TEST(Npy, RejectsMalformedFilesNamingTheOrigin) {
  const std::string good = npy_bytes(std::vector<double>{1.0, 2.0});
  EXPECT_THROW_MSG(parse_npy("not numpy at all", "x.npy"), FormatError, "x.npy: not a .npy file");
  EXPECT_THROW_MSG(parse_npy(good.substr(0, good.size() - 3), "x.npy"), FormatError, "bytes");
  EXPECT_THROW_MSG(parse_npy(good.substr(0, 20), "x.npy"), FormatError, "truncated");
  EXPECT_NE(format_error_of([] {
              parse_npy(npy_with("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }", std::string(48, '\0')), "x.npy");
            }).find("not one-dimensional"),
            std::string::npos);
  EXPECT_NE(format_error_of([] {
              parse_npy(npy_with("{'descr': '<i8', 'fortran_order': False, 'shape': (1,), }", std::string(8, '\0')), "x.npy");
            }).find("dtype"),
            std::string::npos);
}

// A declared shape is outside input: (2**62,) float64 needs 2^65 bytes, which
// wraps to 0 in size_t arithmetic and used to "match" an empty data section,
// then ask for 2^62 doubles. Every such shape must be a FormatError naming the
// shape before any size arithmetic (fuzz_npy; corpus crasher
// tests/fuzz/corpus/fuzz_npy/crash-shape-2pow62.npy).
TEST(Npy, HugeDeclaredShapeIsRejectedBeforeSizeArithmetic) {
  const auto header = [](const std::string& shape) {
    return "{'descr': '<f8', 'fortran_order': False, 'shape': " + shape + ", }";
  };
  for (const std::string shape : {"(4611686018427387904,)", "(2305843009213693952,)", "(1, 4611686018427387904)",
                                  "(18446744073709551615,)", "(99999999999999999999999999,)"}) {
    SCOPED_TRACE(shape);
    const std::string what = format_error_of([&] { parse_npy(npy_with(header(shape), ""), "huge.npy"); });
    EXPECT_NE(what.find("huge.npy: .npy shape " + shape + " declares"), std::string::npos) << what;
    // Some data bytes do not make a declared size plausible either.
    EXPECT_NE(format_error_of([&] { parse_npy(npy_with(header(shape), std::string(64, '\0')), "huge.npy"); }).find("declares"),
              std::string::npos);
  }
  // A product of dimensions that overflows size_t is rejected the same way.
  EXPECT_NE(format_error_of([&] { parse_npy(npy_with(header("(4294967296, 4294967296)"), ""), "x.npy"); }).find("declares"),
            std::string::npos);
  // An honest shape still reads, including an empty one.
  EXPECT_EQ(parse_npy(npy_with(header("(0,)"), ""), "x.npy").size(), 0u);
  EXPECT_EQ(parse_npy(npy_with(header("(2,)"), raw_bytes<double>({0.25, 0.75})), "x.npy"), (std::vector<double>{0.25, 0.75}));
}

RC_GTEST_PROP(Csv, ColumnsRoundTripExactly, ()) {
  const auto n = *rc::gen::inRange<std::size_t>(1, 200);
  std::vector<double> a(n), b(n);
  for (std::size_t i = 0; i < n; ++i) {
    a[i] = std::bit_cast<double>(*rc::gen::arbitrary<std::uint64_t>());
    b[i] = *rc::gen::arbitrary<double>();
    if (!std::isfinite(a[i])) a[i] = -0.25;
    if (!std::isfinite(b[i])) b[i] = 1e-300;
  }
  const std::string text = csv_columns("position_mm", "amplitude", a, b);
  RC_ASSERT(text.rfind("position_mm,amplitude\n", 0) == 0u);
  const auto [pa, pb] = parse_csv_columns(text, "t.csv");
  RC_ASSERT(pa.size() == n);
  for (std::size_t i = 0; i < n; ++i) {
    RC_ASSERT(std::bit_cast<std::uint64_t>(pa[i]) == std::bit_cast<std::uint64_t>(a[i]));
    RC_ASSERT(std::bit_cast<std::uint64_t>(pb[i]) == std::bit_cast<std::uint64_t>(b[i]));
  }
}

TEST(Csv, ParsesSeparatorsCommentsAndCrlf) {
  const auto [a, b] = parse_csv_columns("x,y\r\n# note\r\n1,2\r\n3;4\n5\t6\n 7 , 8 \n\n", "t.csv");
  EXPECT_EQ(a, (std::vector<double>{1, 3, 5, 7}));
  EXPECT_EQ(b, (std::vector<double>{2, 4, 6, 8}));
  const auto [c, d] = parse_csv_columns("1,2\n", "t.csv");  // no header
  EXPECT_EQ(c, std::vector<double>{1});
}

TEST(Csv, RejectsMalformedRowsNamingTheLine) {
  EXPECT_THROW_MSG(parse_csv_columns("x,y\n1,2\n3,four\n", "t.csv"), FormatError, "t.csv:3");
  EXPECT_THROW_MSG(parse_csv_columns("1,2\n3\n", "t.csv"), FormatError, "t.csv:2");
  EXPECT_THROW_MSG(parse_csv_columns("1,2x\n", "t.csv"), FormatError, "t.csv");  // trailing junk
  EXPECT_THROW_MSG(parse_csv_columns("x,y\n", "t.csv"), FormatError, "no numeric rows");
  EXPECT_THROW_MSG(parse_csv_columns("", "t.csv"), FormatError, "no numeric rows");
}

TEST(AtomicWrite, WritesTheBytesAndLeavesNoTemporary) {
  TempDir d;
  const std::string path = d.at("out.bin");
  std::string data(100000, '\0');
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<char>(i * 7);
  write_file_atomic(path, data);
  EXPECT_EQ(read_file(path), data);
  EXPECT_EQ(d.listing(), std::set<std::string>{"out.bin"});
  // Permissions are the usual 0666 & ~umask, not mkstemp's 0600.
  const mode_t mask = ::umask(0);
  ::umask(mask);
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0666 & ~mask);
  // Replacing an existing file.
  write_file_atomic(path, std::string_view("short"));
  EXPECT_EQ(read_file(path), "short");
  EXPECT_EQ(d.listing(), std::set<std::string>{"out.bin"});
}

TEST(AtomicWrite, FailsCleanlyWhenTheDirectoryIsUnusable) {
  TempDir d;
  EXPECT_THROW(write_file_atomic(d.at("missing/out.bin"), std::string_view("x")), IoError);
  write_file_atomic(d.at("file"), std::string_view("x"));
  EXPECT_THROW(write_file_atomic(d.at("file/out.bin"), std::string_view("x")), IoError);  // parent is a file
  fs::create_directories(d.path / "dir");
  EXPECT_THROW(write_file_atomic(d.at("dir"), std::string_view("x")), IoError);  // target is a directory
  EXPECT_EQ(d.listing(), (std::set<std::string>{"file", "dir"}));
  EXPECT_TRUE(fs::is_empty(d.path / "dir"));
  EXPECT_THROW(check_writable(""), IoError);
  try {
    check_writable(d.at("missing/out.bin"));
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("missing/out.bin"), std::string::npos) << e.what();
  }
  if (::geteuid() != 0) {  // root ignores directory permissions
    fs::permissions(d.path / "dir", fs::perms::owner_read | fs::perms::owner_exec);
    EXPECT_THROW(write_file_atomic(d.at("dir/out.bin"), std::string_view("x")), IoError);
    fs::permissions(d.path / "dir", fs::perms::owner_all);
  }
}

TEST(ReadFile, NamesThePathOnFailure) {
  TempDir d;
  try {
    read_file(d.at("nope.json"));
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("nope.json"), std::string::npos);
  }
  EXPECT_THROW(read_file(d.path.string()), IoError);
}

TEST(OutputExtension, LowerCaseAndCompound) {
  EXPECT_EQ(output_extension("a.bin"), ".bin");
  EXPECT_EQ(output_extension("dir/A.BIN"), ".bin");
  EXPECT_EQ(output_extension("x/t.texel.json"), ".texel.json");
  EXPECT_EQ(output_extension("t.json"), ".json");
  EXPECT_EQ(output_extension("noext"), "");
  EXPECT_EQ(output_extension(".hidden"), "");
  EXPECT_EQ(output_extension("dir.d/file"), "");
  EXPECT_EQ(output_extension(".texel.json"), ".json");
}
