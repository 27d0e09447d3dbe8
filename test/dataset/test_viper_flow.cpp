// VIPER .npz flow files: round trips through our writer and reader, the variants numpy writes
// (stored / deflated, float16 / float32, C / Fortran order, byte orders), and damaged files.
#include "viper/dataset/float16.h"
#include "viper/dataset/npy.h"
#include "viper/dataset/viper_flow.h"
#include "viper/dataset/zip_archive.h"

#include "dataset_test_util.h"
#include "flow_test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

namespace {

using namespace viper::dataset;
using namespace viper_dataset_test;

constexpr float kInf = std::numeric_limits<float>::infinity();

// 7x5 flow: a smooth field with the special values planted in it.
FlowImage specialFlow() {
  FlowImage f = zeroFlow(7, 5);
  for (uint32_t y = 0; y < f.height; ++y)
    for (uint32_t x = 0; x < f.width; ++x) {
      f.uv[2 * (y * f.width + x)] = 0.25f * x - 1.0f;
      f.uv[2 * (y * f.width + x) + 1] = -0.5f * y + 0.125f * x;
    }
  const float specials[] = {std::nanf(""), kInf, -kInf, -3.75f, 1e-6f /* half subnormal */, -6e-8f,
                            60000.0f, 70000.0f /* overflows */, -1e20f /* overflows */, 0.1f, -0.0f, 1e-9f};
  for (size_t i = 0; i < sizeof specials / sizeof specials[0]; ++i) f.uv[3 * i + 1] = specials[i];
  return f;
}

// The float16 nearest to each value, widened again: what a VIPER file can hold.
std::vector<float> asStored(const std::vector<float>& values) {
  std::vector<float> out;
  for (float v : values) out.push_back(halfToFloat(floatToHalf(v)));
  return out;
}

void expectSameValues(const std::vector<float>& expected, const std::vector<float>& got, const std::string& context) {
  ASSERT_EQ(expected.size(), got.size()) << context;
  for (size_t i = 0; i < expected.size(); ++i) {
    if (std::isnan(expected[i])) EXPECT_TRUE(std::isnan(got[i])) << context << " value " << i;
    else {
      uint32_t a, b;
      std::memcpy(&a, &expected[i], 4);
      std::memcpy(&b, &got[i], 4);
      EXPECT_EQ(a, b) << context << " value " << i << ": expected " << expected[i] << ", got " << got[i];
    }
  }
}

TEST(ViperFlow, RoundTripStoredAndDeflated) {
  TempDir dir;
  const FlowImage flow = specialFlow();
  for (int level : {0, 1, 6, 9}) {
    const std::string path = dir / ("flow_" + std::to_string(level) + ".npz");
    ZipWriteOptions zip;
    zip.deflate_level = level;
    const ViperFlowWriteStats stats = writeViperFlow(path, flow, zip);
    EXPECT_EQ(stats.overflowed, 2u) << "70000 and -1e20 are beyond float16";
    const FlowImage back = readViperFlow(path);
    EXPECT_EQ(back.width, 7u);
    EXPECT_EQ(back.height, 5u);
    expectSameValues(asStored(flow.uv), back.uv, "level " + std::to_string(level));
  }
}

TEST(ViperFlow, StoredValuesAreTheNearestHalves) {
  TempDir dir;
  const FlowImage flow = specialFlow();
  writeViperFlow(dir / "f.npz", flow);
  const FlowImage back = readViperFlow(dir / "f.npz");
  // Hand-computed halves of the planted values (index 3*i + 1 of uv).
  EXPECT_TRUE(std::isnan(back.uv[1]));
  EXPECT_EQ(back.uv[4], kInf);
  EXPECT_EQ(back.uv[7], -kInf);
  EXPECT_EQ(back.uv[10], -3.75f);
  EXPECT_EQ(back.uv[13], 17 * 0x1p-24f);  // 1e-6 / 2^-24 = 16.78 -> 17 subnormal units
  EXPECT_EQ(back.uv[16], -0x1p-24f);      // 6e-8 / 2^-24 = 1.007 -> 1 unit
  EXPECT_EQ(back.uv[19], 60000.0f);       // a multiple of the spacing 32 there
  EXPECT_EQ(back.uv[22], kInf);
  EXPECT_EQ(back.uv[25], -kInf);
  EXPECT_EQ(back.uv[28], 0.0999755859375f);
  EXPECT_TRUE(back.uv[31] == 0.0f && std::signbit(back.uv[31]));
  EXPECT_EQ(back.uv[34], 0.0f);  // 1e-9 is below half the smallest subnormal
}

TEST(ViperFlow, FileLayoutIsNumpys) {
  TempDir dir;
  const FlowImage flow = specialFlow();
  ZipWriteOptions stored;
  stored.deflate_level = 0;
  writeViperFlow(dir / "f.npz", flow, stored);
  const ZipReader zip(dir / "f.npz");
  EXPECT_EQ(zip.names(), (std::vector<std::string>{"u.npy", "v.npy"}));
  const std::vector<uint8_t> u = zip.read("u.npy");
  // numpy.save's bytes: magic, version 1.0, header length 118, header, 64-byte aligned data.
  const std::string head(u.begin(), u.begin() + 128);
  const std::string expected_dict = "{'descr': '<f2', 'fortran_order': False, 'shape': (5, 7), }";
  EXPECT_EQ(head.substr(0, 8), std::string("\x93NUMPY\x01\x00", 8));
  EXPECT_EQ(u[8] | (u[9] << 8), 118);
  EXPECT_EQ(head.substr(10, expected_dict.size()), expected_dict);
  EXPECT_EQ(head.back(), '\n');
  EXPECT_EQ(u.size(), 128u + 2 * 35);
  // u of pixel (x=1, y=0) is -0.75 = half 0xba00, stored little-endian.
  EXPECT_EQ(u[128 + 2], 0x00);
  EXPECT_EQ(u[128 + 3], 0xba);
}

TEST(ViperFlow, EqualInputsGiveEqualFiles) {
  TempDir dir;
  const FlowImage flow = specialFlow();
  writeViperFlow(dir / "a.npz", flow);
  writeViperFlow(dir / "b.npz", flow);
  EXPECT_EQ(readBytes(dir / "a.npz"), readBytes(dir / "b.npz"));
}

TEST(ViperFlow, DeflateShrinksSmoothFlow) {
  TempDir dir;
  FlowImage flow = zeroFlow(320, 240);
  for (size_t i = 0; i < flow.pixels(); ++i) {
    flow.uv[2 * i] = 2.0f;
    flow.uv[2 * i + 1] = static_cast<float>(i / 320) * 0.01f;
  }
  ZipWriteOptions stored, deflated;
  stored.deflate_level = 0;
  deflated.deflate_level = 1;
  writeViperFlow(dir / "s.npz", flow, stored);
  writeViperFlow(dir / "d.npz", flow, deflated);
  const size_t s = readBytes(dir / "s.npz").size(), d = readBytes(dir / "d.npz").size();
  EXPECT_GE(s, 4 * flow.pixels());
  EXPECT_LT(d, s / 4);
  expectSameValues(readViperFlow(dir / "s.npz").uv, readViperFlow(dir / "d.npz").uv, "stored vs deflated");
}

// An npz made entry by entry, for the variants and damage below.
ZipEntry npyEntry(const std::string& name, const NpyArray& a) { return ZipEntry{name, encodeNpy(a)}; }

NpyArray array(const std::string& descr, std::vector<uint64_t> shape, const std::vector<float>& values,
               bool fortran = false) {
  NpyArray a;
  a.descr = descr;
  a.shape = std::move(shape);
  a.fortran_order = fortran;
  const bool big = descr[0] == '>';
  for (float v : values) {
    uint8_t b[4];
    size_t n = 0;
    if (descr.substr(1) == "f2") {
      const uint16_t h = floatToHalf(v);
      b[0] = h & 0xff;
      b[1] = h >> 8;
      n = 2;
    } else {
      uint32_t x;
      std::memcpy(&x, &v, 4);
      for (int i = 0; i < 4; ++i) b[i] = static_cast<uint8_t>(x >> (8 * i));
      n = 4;
    }
    if (big) std::reverse(b, b + n);
    a.data.insert(a.data.end(), b, b + n);
  }
  return a;
}

TEST(ViperFlow, ReadsFloat32FortranAndBigEndianArrays) {
  TempDir dir;
  // A 2x3 field, rows (0, 1, 2) and (3, 4, 5) for u, negated for v.
  const std::vector<float> rowmajor = {0.5f, 1, 2, 3, 4, 5.25f};
  const std::vector<float> colmajor = {0.5f, 3, 1, 4, 2, 5.25f};
  std::vector<float> neg_row, neg_col;
  for (float x : rowmajor) neg_row.push_back(-x);
  for (float x : colmajor) neg_col.push_back(-x);
  struct Variant {
    std::string descr;
    bool fortran;
  };
  for (const Variant& var : {Variant{"<f2", false}, Variant{"<f4", false}, Variant{"<f2", true},
                             Variant{"<f4", true}, Variant{">f2", false}, Variant{">f4", true}}) {
    const std::string path = dir / "v.npz";
    writeZip(path, {npyEntry("u.npy", array(var.descr, {2, 3}, var.fortran ? colmajor : rowmajor, var.fortran)),
                    npyEntry("v.npy", array(var.descr, {2, 3}, var.fortran ? neg_col : neg_row, var.fortran))});
    const FlowImage f = readViperFlow(path);
    const std::string context = var.descr + (var.fortran ? " Fortran" : " C");
    ASSERT_EQ(f.width, 3u) << context;
    ASSERT_EQ(f.height, 2u) << context;
    for (size_t i = 0; i < 6; ++i) {
      EXPECT_EQ(f.uv[2 * i], rowmajor[i]) << context << " u " << i;
      EXPECT_EQ(f.uv[2 * i + 1], -rowmajor[i]) << context << " v " << i;
    }
  }
}

TEST(ViperFlow, Float32EntriesKeepTheirPrecision) {
  TempDir dir;
  const std::vector<float> u = {0.1f, 1e-40f, 123456.78f, std::nanf("")};
  const std::vector<float> v = {-0.1f, kInf, -123456.78f, 3.0f};
  writeZip(dir / "f4.npz", {npyEntry("u.npy", array("<f4", {2, 2}, u)), npyEntry("v.npy", array("<f4", {2, 2}, v))});
  const FlowImage f = readViperFlow(dir / "f4.npz");
  std::vector<float> gu, gv;
  for (size_t i = 0; i < 4; ++i) {
    gu.push_back(f.uv[2 * i]);
    gv.push_back(f.uv[2 * i + 1]);
  }
  expectSameValues(u, gu, "u");
  expectSameValues(v, gv, "v");
}

TEST(ViperFlow, OtherEntriesAreIgnored) {
  TempDir dir;
  const std::vector<float> x = {1, 2};
  writeZip(dir / "extra.npz", {npyEntry("mask.npy", array("<f4", {3}, {1, 2, 3})), npyEntry("v.npy", array("<f2", {1, 2}, x)),
                               npyEntry("u.npy", array("<f2", {1, 2}, x))});
  const FlowImage f = readViperFlow(dir / "extra.npz");
  EXPECT_EQ(f.uv, (std::vector<float>{1, 1, 2, 2}));
}

TEST(ViperFlow, WriterRejectsInconsistentFlow) {
  TempDir dir;
  FlowImage f;
  f.width = 3;
  f.height = 2;
  f.uv.resize(11);
  EXPECT_THROW(writeViperFlow(dir / "x.npz", f), std::invalid_argument);
  f.width = 0;
  f.uv.clear();
  EXPECT_THROW(writeViperFlow(dir / "x.npz", f), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir / "x.npz"));
}

TEST(ViperFlow, WriteIntoMissingFolderNamesTheFile) {
  TempDir dir;
  const std::string path = dir / "no/such/folder/f.npz";
  expectErrorNaming([&] { writeViperFlow(path, specialFlow()); }, {path}, "missing folder");
}

// Each damaged file must give a std::runtime_error naming the file (and the entry where there is one).
TEST(ViperFlow, DamagedFilesGiveErrorsNamingTheFile) {
  TempDir dir;
  const std::vector<float> six = {1, 2, 3, 4, 5, 6};
  const std::string good = dir / "good.npz";
  writeViperFlow(good, specialFlow());
  const std::vector<uint8_t> good_bytes = readBytes(good);

  const std::string missing = dir / "missing.npz";
  expectErrorNaming([&] { readViperFlow(missing); }, {missing}, "missing file");

  const std::string text = dir / "text.npz";
  writeBytes(text, std::vector<uint8_t>(100, 'x'));
  expectErrorNaming([&] { readViperFlow(text); }, {text, "zip"}, "not a zip");

  const std::string empty = dir / "empty.npz";
  writeBytes(empty, {});
  expectErrorNaming([&] { readViperFlow(empty); }, {empty}, "empty file");

  const std::string truncated = dir / "truncated.npz";
  writeBytes(truncated, std::vector<uint8_t>(good_bytes.begin(), good_bytes.begin() + good_bytes.size() / 2));
  expectErrorNaming([&] { readViperFlow(truncated); }, {truncated}, "truncated zip");

  const std::string no_v = dir / "no_v.npz";
  writeZip(no_v, {npyEntry("u.npy", array("<f2", {2, 3}, six))});
  expectErrorNaming([&] { readViperFlow(no_v); }, {no_v, "v.npy", "missing"}, "missing entry");

  const std::string ints = dir / "ints.npz";
  NpyArray i4 = array("<f4", {2, 3}, six);
  i4.descr = "<i4";
  writeZip(ints, {ZipEntry{"u.npy", encodeNpy(i4)}, npyEntry("v.npy", array("<f2", {2, 3}, six))});
  expectErrorNaming([&] { readViperFlow(ints); }, {ints, "u.npy", "<i4"}, "wrong dtype");

  const std::string f8 = dir / "f8.npz";
  NpyArray d = array("<f4", {1, 3}, six);
  d.descr = "<f8";
  writeZip(f8, {npyEntry("u.npy", array("<f2", {2, 3}, six)), ZipEntry{"v.npy", encodeNpy(d)}});
  expectErrorNaming([&] { readViperFlow(f8); }, {f8, "v.npy", "<f8"}, "float64");

  const std::string three_d = dir / "3d.npz";
  writeZip(three_d, {npyEntry("u.npy", array("<f2", {1, 2, 3}, six)), npyEntry("v.npy", array("<f2", {2, 3}, six))});
  expectErrorNaming([&] { readViperFlow(three_d); }, {three_d, "u.npy", "3 dimensions"}, "3-D");

  const std::string one_d = dir / "1d.npz";
  writeZip(one_d, {npyEntry("u.npy", array("<f2", {6}, six)), npyEntry("v.npy", array("<f2", {6}, six))});
  expectErrorNaming([&] { readViperFlow(one_d); }, {one_d, "u.npy", "1 dimensions"}, "1-D");

  const std::string zero = dir / "zero.npz";
  writeZip(zero, {npyEntry("u.npy", array("<f2", {0, 3}, {})), npyEntry("v.npy", array("<f2", {0, 3}, {}))});
  expectErrorNaming([&] { readViperFlow(zero); }, {zero, "u.npy", "empty"}, "empty shape");

  const std::string mismatch = dir / "mismatch.npz";
  writeZip(mismatch, {npyEntry("u.npy", array("<f2", {2, 3}, six)), npyEntry("v.npy", array("<f2", {3, 2}, six))});
  expectErrorNaming([&] { readViperFlow(mismatch); }, {mismatch, "(2, 3)", "(3, 2)"}, "u/v shape mismatch");

  const std::string magic = dir / "magic.npz";
  std::vector<uint8_t> bad_magic = encodeNpy(array("<f2", {2, 3}, six));
  bad_magic[1] = 'X';
  writeZip(magic, {ZipEntry{"u.npy", bad_magic}, npyEntry("v.npy", array("<f2", {2, 3}, six))});
  expectErrorNaming([&] { readViperFlow(magic); }, {magic + ":u.npy", "magic"}, "bad npy magic");

  const std::string short_data = dir / "short_data.npz";
  std::vector<uint8_t> cut = encodeNpy(array("<f2", {2, 3}, six));
  cut.resize(cut.size() - 3);
  writeZip(short_data, {npyEntry("u.npy", array("<f2", {2, 3}, six)), ZipEntry{"v.npy", cut}});
  expectErrorNaming([&] { readViperFlow(short_data); }, {short_data + ":v.npy", "needs 12"}, "npy data truncated");

  const std::string short_header = dir / "short_header.npz";
  std::vector<uint8_t> head = encodeNpy(array("<f2", {2, 3}, six));
  head.resize(40);
  writeZip(short_header, {ZipEntry{"u.npy", head}, npyEntry("v.npy", array("<f2", {2, 3}, six))});
  expectErrorNaming([&] { readViperFlow(short_header); }, {short_header + ":u.npy", "truncated npy header"},
                    "npy header truncated");

  const std::string bad_key = dir / "bad_key.npz";
  std::vector<uint8_t> keyed = encodeNpy(array("<f2", {2, 3}, six));
  std::memcpy(keyed.data() + 12, "dexcr", 5);  // {'descr' -> {'dexcr'
  writeZip(bad_key, {ZipEntry{"u.npy", keyed}, npyEntry("v.npy", array("<f2", {2, 3}, six))});
  expectErrorNaming([&] { readViperFlow(bad_key); }, {bad_key + ":u.npy", "dexcr", "offset"}, "unknown header key");

  const std::string bad_version = dir / "bad_version.npz";
  std::vector<uint8_t> v9 = encodeNpy(array("<f2", {2, 3}, six));
  v9[6] = 9;
  writeZip(bad_version, {ZipEntry{"u.npy", v9}, npyEntry("v.npy", array("<f2", {2, 3}, six))});
  expectErrorNaming([&] { readViperFlow(bad_version); }, {bad_version + ":u.npy", "version 9.0"}, "npy version");

  // A flipped byte inside an entry's data: the CRC (stored) or the inflater (deflated) catch it.
  for (int level : {0, 6}) {
    const std::string flipped = dir / ("flipped_" + std::to_string(level) + ".npz");
    ZipWriteOptions zip;
    zip.deflate_level = level;
    writeViperFlow(flipped, specialFlow(), zip);
    std::vector<uint8_t> bytes = readBytes(flipped);
    // The first local header is 30 bytes + "u.npy"; its data follows.
    bytes[30 + 5 + 40] ^= 0x5a;
    writeBytes(flipped, bytes);
    expectErrorNaming([&] { readViperFlow(flipped); }, {flipped, "u.npy", "damaged"},
                      "flipped byte, level " + std::to_string(level));
  }
}

// Random damage (flipped bytes, cuts) gives a flow or a std::runtime_error naming the file, never
// a crash or another exception.
TEST(ViperFlow, RandomDamageGivesErrorsOrFlow) {
  TempDir dir;
  std::mt19937 rng(11);
  for (int level : {0, 1}) {
    ZipWriteOptions zip;
    zip.deflate_level = level;
    writeViperFlow(dir / "good.npz", specialFlow(), zip);
    const std::vector<uint8_t> good = readBytes(dir / "good.npz");
    size_t errors = 0;
    for (int trial = 0; trial < 300; ++trial) {
      std::vector<uint8_t> bytes = good;
      if (trial % 3 == 0) {
        bytes.resize(std::uniform_int_distribution<size_t>(0, bytes.size() - 1)(rng));
      } else {
        for (int k = 0; k <= trial % 4; ++k)
          bytes[std::uniform_int_distribution<size_t>(0, bytes.size() - 1)(rng)] ^=
              static_cast<uint8_t>(std::uniform_int_distribution<int>(1, 255)(rng));
      }
      errors += readsOrNamesTheFile(dir / "damaged.npz", bytes, [](const std::string& p) { return readViperFlow(p); });
    }
    EXPECT_GT(errors, 200u) << "level " << level;
  }
}

}  // namespace
