// SPDX-License-Identifier: Apache-2.0
// Segmented SDO (CiA 301 7.2.4.3): SdoClient against SdoServer frame by frame over an object
// dictionary with byte-string entries, on a virtual clock. Sizes, toggle bits, size
// indications, timeouts on both sides, buffers, aborts, and the frames byte for byte.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "frame_helpers.hpp"
#include "settle/hal/canopen/object_dictionary.hpp"
#include "settle/hal/canopen/sdo.hpp"

namespace settle::hal::canopen {
namespace {

using Bytes = std::vector<std::uint8_t>;

constexpr NodeId node = 9;
constexpr std::uint16_t domain_index = 0x2100;  // rw DOMAIN, 4096 bytes
constexpr std::uint16_t name_index = 0x2101;    // ro VISIBLE_STRING
constexpr std::uint16_t label_index = 0x2102;   // rw VISIBLE_STRING, 16 bytes
constexpr std::uint16_t word_index = 0x2103;    // rw UNSIGNED32
constexpr std::uint32_t server_timeout_us = 20'000;
constexpr std::uint32_t client_timeout_us = 50'000;

Bytes pattern(std::size_t n) {
  Bytes b(n);
  for (std::size_t i = 0; i < n; ++i) {
    b[i] = static_cast<std::uint8_t>((i * 31U + 7U) & 0xFFU);
  }
  return b;
}

Bytes text(const char* s) {
  Bytes b;
  for (; *s != '\0'; ++s) {
    b.push_back(static_cast<std::uint8_t>(*s));
  }
  return b;
}

Bytes view_of(std::span<const std::uint8_t> v) { return {v.begin(), v.end()}; }

class SdoSegmented : public ::testing::Test {
 protected:
  OdByteString<4096> domain;
  OdByteString<16> name;
  OdByteString<16> label;
  std::uint32_t word{0x1122'3344};
  std::array<OdEntry, 4> entries{{
      od_bytes_entry(domain_index, 0, domain.bytes(), OdType::domain, OdAccess::rw),
      od_bytes_entry(name_index, 0, name.bytes(), OdType::visible_string, OdAccess::ro),
      od_bytes_entry(label_index, 0, label.bytes(), OdType::visible_string, OdAccess::rw),
      od_entry(word_index, 0, word, OdAccess::rw),
  }};
  ObjectDictionary od{entries};
  std::array<std::uint8_t, 4096> staging{};
  SdoServer server{node, od, server_timeout_us, staging};
  SdoClient client{node, client_timeout_us};
  FrameBuffer<4> to_server;
  FrameBuffer<4> to_client;
  std::vector<CanFrame> trace;  // every frame, in bus order
  std::uint64_t now_us{0};

  void SetUp() override {
    ASSERT_TRUE(od.is_well_formed());
    name.assign("Settle axis X");
  }

  // Delivers frames both ways until the bus is quiet; each delivery happens at now_us.
  void run() {
    for (int guard = 0; guard < 100'000; ++guard) {
      if (!to_server.empty()) {
        const std::vector<CanFrame> frames{to_server.frames().begin(), to_server.frames().end()};
        to_server.clear();
        for (const CanFrame& f : frames) {
          trace.push_back(f);
          EXPECT_TRUE(server.on_frame(f, now_us, to_client));
        }
      } else if (!to_client.empty()) {
        const std::vector<CanFrame> frames{to_client.frames().begin(), to_client.frames().end()};
        to_client.clear();
        for (const CanFrame& f : frames) {
          trace.push_back(f);
          (void)client.on_frame(f, now_us, to_server);
        }
      } else {
        return;
      }
    }
    ADD_FAILURE() << "the transfer did not settle";
  }

  // One request straight to the server; returns its only answer.
  Bytes ask(const CanFrame& request) {
    to_client.clear();
    EXPECT_TRUE(server.on_frame(request, now_us, to_client));
    EXPECT_EQ(to_client.size(), 1U) << "every request gets exactly one answer";
    const Bytes b = to_client.empty() ? Bytes{} : test::bytes_of(to_client[0]);
    to_client.clear();
    return b;
  }

  static CanFrame raw(std::initializer_list<std::uint8_t> bytes) { return test::frame(0x600U + node, bytes); }

  // The bus saw exactly these frames (id, bytes), in this order.
  void expect_trace(const std::vector<std::pair<std::uint32_t, Bytes>>& expected) const {
    ASSERT_EQ(trace.size(), expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
      EXPECT_EQ(trace[i].id, expected[i].first) << "frame " << i;
      EXPECT_EQ(test::bytes_of(trace[i]), expected[i].second) << "frame " << i;
    }
  }
};

// ---- Sizes, both ways ----

class SdoSegmentedSizes : public SdoSegmented, public ::testing::WithParamInterface<std::size_t> {};

TEST_P(SdoSegmentedSizes, DownloadThenUploadCarriesEveryByte) {
  const std::size_t n = GetParam();
  const Bytes data = pattern(n);
  domain.assign("stale");  // the download must replace it, length included

  ASSERT_TRUE(client.download_bytes(domain_index, 0, data, now_us, to_server));
  run();
  ASSERT_EQ(client.status(), SdoClientStatus::done) << "abort 0x" << std::hex << client.result().abort_raw;
  EXPECT_EQ(client.result().length, n);
  EXPECT_EQ(view_of(domain.view()), data);
  EXPECT_FALSE(server.busy());
  // Expedited for 1..4 bytes (request + answer); otherwise initiate + answer, then a segment
  // and its answer per started seven bytes (one empty segment for zero bytes).
  const std::size_t segments = n == 0 ? 1 : (n + 6) / 7;
  EXPECT_EQ(trace.size(), n >= 1 && n <= 4 ? 2U : 2U + 2U * segments);

  trace.clear();
  std::vector<std::uint8_t> buffer(4096, 0xEE);
  ASSERT_TRUE(client.upload_bytes(domain_index, 0, buffer, now_us, to_server));
  run();
  ASSERT_EQ(client.status(), SdoClientStatus::done) << "abort 0x" << std::hex << client.result().abort_raw;
  ASSERT_EQ(client.result().length, n);
  EXPECT_EQ(Bytes(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(n)), data);
  if (n < buffer.size()) {
    EXPECT_EQ(buffer[n], 0xEE) << "nothing written past the object";
  }
  EXPECT_EQ(trace.size(), n >= 1 && n <= 4 ? 2U : 2U + 2U * segments);
  EXPECT_FALSE(server.busy());
}

INSTANTIATE_TEST_SUITE_P(Bytes, SdoSegmentedSizes, ::testing::Values(0U, 1U, 7U, 8U, 889U, 4096U),
                         [](const ::testing::TestParamInfo<std::size_t>& p) { return "n" + std::to_string(p.param); });

TEST_F(SdoSegmented, IntegerObjectsGoSegmentedToo) {
  // A client may download any object segmented; an integer takes exactly its size.
  const std::uint8_t four[] = {0x78, 0x56, 0x34, 0x12};
  EXPECT_EQ(ask(encode_sdo_download_segmented_request(node, word_index, 0, 4)), (Bytes{0x60, 0x03, 0x21, 0x00, 0, 0, 0, 0}));
  EXPECT_EQ(ask(encode_sdo_download_segment(node, false, four, true)), (Bytes{0x20, 0, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(word, 0x1234'5678U);
  EXPECT_EQ(ask(encode_sdo_download_segmented_request(node, word_index, 0, 3)),
            (Bytes{0x80, 0x03, 0x21, 0x00, 0x13, 0x00, 0x07, 0x06}))
      << "three bytes for a four-byte object: length too low";
  EXPECT_EQ(ask(encode_sdo_download_segmented_request(node, word_index, 0, 5)),
            (Bytes{0x80, 0x03, 0x21, 0x00, 0x12, 0x00, 0x07, 0x06}));
  EXPECT_EQ(word, 0x1234'5678U);
}

TEST_F(SdoSegmented, ASegmentWithNoDataThatIsNotTheLastIsAborted) {
  // Issue 34: 100 000 empty segments were each answered; the first is now refused and the
  // transfer ends, the object as it was.
  label.assign("kept");
  for (const bool size_indicated : {true, false}) {
    SCOPED_TRACE(size_indicated);
    const CanFrame initiate = size_indicated ? encode_sdo_download_segmented_request(node, label_index, 0, 10)
                                             : raw({0x20, 0x02, 0x21, 0x00, 0, 0, 0, 0});
    ASSERT_EQ(ask(initiate)[0], 0x60);
    // cs 0, t 0, n 7 (no data), c 0
    EXPECT_EQ(ask(raw({0x0E, 0, 0, 0, 0, 0, 0, 0})), (Bytes{0x80, 0x02, 0x21, 0x00, 0x01, 0x00, 0x04, 0x05}));
    EXPECT_FALSE(server.busy());
    EXPECT_EQ(view_of(label.view()), text("kept"));
  }
  // An empty last segment is a transfer of zero bytes, as before.
  ASSERT_EQ(ask(encode_sdo_download_segmented_request(node, label_index, 0, 0))[0], 0x60);
  EXPECT_EQ(ask(raw({0x0F, 0, 0, 0, 0, 0, 0, 0}))[0], 0x20);
  EXPECT_TRUE(label.view().empty());
}

TEST_F(SdoSegmented, MoreSegmentsThanTheIndicatedSizeAllowsAreAborted06070012) {
  // Four bytes announced, one per segment: four segments carry them, a fifth is too many.
  const std::uint8_t one[] = {0xAB};
  ASSERT_EQ(ask(encode_sdo_download_segmented_request(node, label_index, 0, 4))[0], 0x60);
  bool toggle = false;
  for (int i = 0; i < 4; ++i) {
    ASSERT_EQ(ask(encode_sdo_download_segment(node, toggle, one, false))[0] & 0xE0, 0x20) << i;
    toggle = !toggle;
  }
  EXPECT_EQ(ask(encode_sdo_download_segment(node, toggle, one, false)),
            (Bytes{0x80, 0x02, 0x21, 0x00, 0x12, 0x00, 0x07, 0x06}));
  EXPECT_FALSE(server.busy());
}

TEST_F(SdoSegmented, AStringWrittenIntoAnIntegerObjectIsRefusedByItsLength) {
  // `drive write --type string` into a UNSIGNED32: the data's size is not the object's.
  EXPECT_EQ(ask(encode_sdo_download_request(node, word_index, 0, 0x0063'6261U, 3)),
            (Bytes{0x80, 0x03, 0x21, 0x00, 0x13, 0x00, 0x07, 0x06})) << "\"abc\", expedited: too low";
  EXPECT_EQ(ask(encode_sdo_download_request(node, word_index, 0, 0x6261U, 2))[4], 0x13);
  EXPECT_EQ(ask(encode_sdo_download_segmented_request(node, word_index, 0, 11)),
            (Bytes{0x80, 0x03, 0x21, 0x00, 0x12, 0x00, 0x07, 0x06})) << "\"hello world\": too high";
  // Segmented without a size: refused at the segment that overflows the object, or at the last
  // when it falls short.
  const Bytes hello = text("hello w");
  ASSERT_EQ(ask(raw({0x20, 0x03, 0x21, 0x00, 0, 0, 0, 0}))[0], 0x60);
  EXPECT_EQ(ask(encode_sdo_download_segment(node, false, hello, false)),
            (Bytes{0x80, 0x03, 0x21, 0x00, 0x12, 0x00, 0x07, 0x06}));
  const Bytes ab = text("ab");
  ASSERT_EQ(ask(raw({0x20, 0x03, 0x21, 0x00, 0, 0, 0, 0}))[0], 0x60);
  EXPECT_EQ(ask(encode_sdo_download_segment(node, false, ab, true)),
            (Bytes{0x80, 0x03, 0x21, 0x00, 0x13, 0x00, 0x07, 0x06}));
  EXPECT_EQ(word, 0x1122'3344U) << "the object is as it was";
}

// ---- Golden frames, written from the CiA 301 layout ----

TEST_F(SdoSegmented, GoldenSegmentedDownloadOfTenBytes) {
  const Bytes data = text("ABCDEFGHIJ");
  ASSERT_TRUE(client.download_bytes(label_index, 0, data, now_us, to_server));
  run();
  ASSERT_EQ(client.status(), SdoClientStatus::done);
  const std::vector<std::pair<std::uint32_t, Bytes>> expected{
      // initiate download: ccs 1, e 0, s 1 -> 0x21; index 0x2102 LE; sub 0; size 10 LE
      {0x609, {0x21, 0x02, 0x21, 0x00, 0x0A, 0x00, 0x00, 0x00}},
      // initiate download response: scs 3 -> 0x60, multiplexer echoed
      {0x589, {0x60, 0x02, 0x21, 0x00, 0x00, 0x00, 0x00, 0x00}},
      // segment 1: ccs 0, t 0, n 0, c 0 -> 0x00; seven bytes
      {0x609, {0x00, 'A', 'B', 'C', 'D', 'E', 'F', 'G'}},
      // segment response: scs 1, t 0 -> 0x20
      {0x589, {0x20, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},
      // segment 2: ccs 0, t 1 (0x10), n 4 (0x08), c 1 -> 0x19; three bytes, then zeros
      {0x609, {0x19, 'H', 'I', 'J', 0x00, 0x00, 0x00, 0x00}},
      // segment response: scs 1, t 1 -> 0x30
      {0x589, {0x30, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},
  };
  expect_trace(expected);
  EXPECT_EQ(view_of(label.view()), data);
}

TEST_F(SdoSegmented, GoldenSegmentedUploadOfThirteenBytes) {
  std::array<std::uint8_t, 16> buffer{};
  ASSERT_TRUE(client.upload_bytes(name_index, 0, buffer, now_us, to_server));
  run();
  ASSERT_EQ(client.status(), SdoClientStatus::done);
  const std::vector<std::pair<std::uint32_t, Bytes>> expected{
      // initiate upload: ccs 2 -> 0x40
      {0x609, {0x40, 0x01, 0x21, 0x00, 0x00, 0x00, 0x00, 0x00}},
      // initiate upload response: scs 2, e 0, s 1 -> 0x41; size 13
      {0x589, {0x41, 0x01, 0x21, 0x00, 0x0D, 0x00, 0x00, 0x00}},
      // upload segment request: ccs 3, t 0 -> 0x60
      {0x609, {0x60, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},
      // upload segment: scs 0, t 0, n 0, c 0 -> 0x00
      {0x589, {0x00, 'S', 'e', 't', 't', 'l', 'e', ' '}},
      // upload segment request: ccs 3, t 1 -> 0x70
      {0x609, {0x70, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}},
      // last segment: scs 0, t 1 (0x10), n 1 (0x02), c 1 -> 0x13; six bytes
      {0x589, {0x13, 'a', 'x', 'i', 's', ' ', 'X', 0x00}},
  };
  expect_trace(expected);
  EXPECT_EQ(client.result().length, 13U);
  EXPECT_EQ(Bytes(buffer.begin(), buffer.begin() + 13), text("Settle axis X"));
}

TEST_F(SdoSegmented, ShortStringsGoExpeditedWithTheirSize) {
  label.assign("abc");
  EXPECT_EQ(ask(encode_sdo_upload_request(node, label_index, 0)), (Bytes{0x47, 0x02, 0x21, 0x00, 'a', 'b', 'c', 0}));
  EXPECT_EQ(ask(encode_sdo_download_request(node, label_index, 0, 0x5A59, 2)), (Bytes{0x60, 0x02, 0x21, 0, 0, 0, 0, 0}));
  EXPECT_EQ(view_of(label.view()), text("YZ"));
}

// ---- Toggle bit ----

TEST_F(SdoSegmented, ServerAbortsAToggleThatDidNotAlternate) {
  EXPECT_EQ(ask(encode_sdo_upload_request(node, name_index, 0))[0], 0x41);
  EXPECT_EQ(ask(raw({0x60, 0, 0, 0, 0, 0, 0, 0}))[0], 0x00);  // t = 0: the first segment
  EXPECT_EQ(ask(raw({0x60, 0, 0, 0, 0, 0, 0, 0})), (Bytes{0x80, 0x01, 0x21, 0x00, 0x00, 0x00, 0x03, 0x05}))
      << "t = 0 again instead of 1: 0x05030000, naming the transfer";
  EXPECT_FALSE(server.busy());
  EXPECT_EQ(ask(encode_sdo_upload_request(node, word_index, 0)), (Bytes{0x43, 0x03, 0x21, 0x00, 0x44, 0x33, 0x22, 0x11}))
      << "the next transfer works";
}

TEST_F(SdoSegmented, ServerAbortsADownloadSegmentWithTheWrongToggleAndKeepsTheObject) {
  label.assign("keep me");
  EXPECT_EQ(ask(encode_sdo_download_segmented_request(node, label_index, 0, 10))[0], 0x60);
  EXPECT_EQ(ask(raw({0x10, 'A', 'B', 'C', 'D', 'E', 'F', 'G'})),
            (Bytes{0x80, 0x02, 0x21, 0x00, 0x00, 0x00, 0x03, 0x05}))
      << "the first segment must carry t = 0";
  EXPECT_EQ(view_of(label.view()), text("keep me"));
  EXPECT_FALSE(server.busy());
}

TEST_F(SdoSegmented, ClientAbortsAnUploadSegmentWithTheWrongToggle) {
  std::array<std::uint8_t, 32> buffer{};
  ASSERT_TRUE(client.upload_bytes(name_index, 0, buffer, now_us, to_server));
  to_server.clear();
  ASSERT_TRUE(client.on_frame(encode_sdo_upload_segmented_response(node, name_index, 0, 13), now_us, to_server));
  to_server.clear();  // the segment request (t = 0)
  const std::uint8_t seven[7] = {1, 2, 3, 4, 5, 6, 7};
  ASSERT_TRUE(client.on_frame(encode_sdo_upload_segment(node, true, seven, false), now_us, to_server));
  EXPECT_EQ(client.status(), SdoClientStatus::aborted);
  EXPECT_EQ(client.result().abort, SdoAbort::toggle_bit);
  ASSERT_EQ(to_server.size(), 1U);
  EXPECT_EQ(test::bytes_of(to_server[0]), (Bytes{0x80, 0x01, 0x21, 0x00, 0x00, 0x00, 0x03, 0x05}));
}

TEST_F(SdoSegmented, ClientAbortsADownloadSegmentResponseWithTheWrongToggle) {
  const Bytes data = pattern(20);
  ASSERT_TRUE(client.download_bytes(domain_index, 0, data, now_us, to_server));
  to_server.clear();
  ASSERT_TRUE(client.on_frame(encode_sdo_download_response(node, domain_index, 0), now_us, to_server));
  to_server.clear();  // segment 1, t = 0
  ASSERT_TRUE(client.on_frame(encode_sdo_download_segment_response(node, true), now_us, to_server));
  EXPECT_EQ(client.result().abort, SdoAbort::toggle_bit);
  ASSERT_EQ(to_server.size(), 1U);
  EXPECT_EQ(test::bytes_of(to_server[0]), (Bytes{0x80, 0x00, 0x21, 0x00, 0x00, 0x00, 0x03, 0x05}));
}

// ---- Size indication ----

TEST_F(SdoSegmented, DownloadLongerThanIndicatedAborts06070012) {
  label.assign("old");
  EXPECT_EQ(ask(encode_sdo_download_segmented_request(node, label_index, 0, 10))[0], 0x60);
  EXPECT_EQ(ask(raw({0x00, 1, 2, 3, 4, 5, 6, 7}))[0], 0x20);
  EXPECT_EQ(ask(raw({0x11, 8, 9, 10, 11, 12, 13, 14})), (Bytes{0x80, 0x02, 0x21, 0x00, 0x12, 0x00, 0x07, 0x06}))
      << "14 bytes where 10 were indicated";
  EXPECT_EQ(view_of(label.view()), text("old"));
}

TEST_F(SdoSegmented, DownloadShorterThanIndicatedAborts06070013) {
  label.assign("old");
  EXPECT_EQ(ask(encode_sdo_download_segmented_request(node, label_index, 0, 10))[0], 0x60);
  EXPECT_EQ(ask(raw({0x01, 1, 2, 3, 4, 5, 6, 7})), (Bytes{0x80, 0x02, 0x21, 0x00, 0x13, 0x00, 0x07, 0x06}))
      << "last segment after 7 of 10 bytes";
  EXPECT_EQ(view_of(label.view()), text("old"));
}

TEST_F(SdoSegmented, DownloadLongerThanTheObjectAborts06070012) {
  EXPECT_EQ(ask(encode_sdo_download_segmented_request(node, label_index, 0, 17)),
            (Bytes{0x80, 0x02, 0x21, 0x00, 0x12, 0x00, 0x07, 0x06}))
      << "indicated: refused at the initiate";
  // Not indicated (e = 0, s = 0): refused at the segment that overflows the 16-byte object.
  EXPECT_EQ(ask(raw({0x20, 0x02, 0x21, 0x00, 0, 0, 0, 0}))[0], 0x60);
  EXPECT_EQ(ask(raw({0x00, 1, 2, 3, 4, 5, 6, 7}))[0], 0x20);
  EXPECT_EQ(ask(raw({0x10, 1, 2, 3, 4, 5, 6, 7}))[0], 0x30);
  EXPECT_EQ(ask(raw({0x01, 1, 2, 3, 4, 5, 6, 7})), (Bytes{0x80, 0x02, 0x21, 0x00, 0x12, 0x00, 0x07, 0x06}));
  // Not indicated and within the object: the length is what the segments carried.
  EXPECT_EQ(ask(raw({0x20, 0x02, 0x21, 0x00, 0, 0, 0, 0}))[0], 0x60);
  EXPECT_EQ(ask(raw({0x03, 'h', 'e', 'l', 'l', 'o', '!', 0}))[0], 0x20) << "0x03: n = 1, c = 1, six bytes";
  EXPECT_EQ(view_of(label.view()), text("hello!"));
}

TEST_F(SdoSegmented, ClientAbortsWhenSegmentsDoNotAddUpToTheIndicatedSize) {
  std::array<std::uint8_t, 64> buffer{};
  ASSERT_TRUE(client.upload_bytes(domain_index, 0, buffer, now_us, to_server));
  ASSERT_TRUE(client.on_frame(encode_sdo_upload_segmented_response(node, domain_index, 0, 10), now_us, to_server));
  const std::uint8_t seven[7] = {1, 2, 3, 4, 5, 6, 7};
  ASSERT_TRUE(client.on_frame(encode_sdo_upload_segment(node, false, seven, true), now_us, to_server));
  EXPECT_EQ(client.status(), SdoClientStatus::aborted);
  EXPECT_EQ(client.result().abort, SdoAbort::length_mismatch) << "7 bytes where the server said 10";

  to_server.clear();
  ASSERT_TRUE(client.upload_bytes(domain_index, 0, buffer, now_us, to_server));
  ASSERT_TRUE(client.on_frame(encode_sdo_upload_segmented_response(node, domain_index, 0, 10), now_us, to_server));
  ASSERT_TRUE(client.on_frame(encode_sdo_upload_segment(node, false, seven, false), now_us, to_server));
  ASSERT_TRUE(client.on_frame(encode_sdo_upload_segment(node, true, seven, true), now_us, to_server));
  EXPECT_EQ(client.result().abort, SdoAbort::length_mismatch) << "14 bytes where the server said 10";
  ASSERT_GE(to_server.size(), 1U);
  EXPECT_EQ(test::bytes_of(to_server[to_server.size() - 1]), (Bytes{0x80, 0x00, 0x21, 0x00, 0x10, 0x00, 0x07, 0x06}));
}

// ---- Buffers ----

TEST_F(SdoSegmented, ObjectLongerThanTheClientsBufferAborts06070012AndNothingOverflows) {
  domain.assign("0123456789");
  std::vector<std::uint8_t> buffer(12, 0xEE);  // guard bytes after the 8 the client may use
  ASSERT_TRUE(client.upload_bytes(domain_index, 0, std::span<std::uint8_t>{buffer}.first(8), now_us, to_server));
  run();
  EXPECT_EQ(client.status(), SdoClientStatus::aborted);
  EXPECT_EQ(client.result().abort, SdoAbort::length_too_high);
  EXPECT_EQ(test::bytes_of(trace.back()), (Bytes{0x80, 0x00, 0x21, 0x00, 0x12, 0x00, 0x07, 0x06}));
  EXPECT_FALSE(server.busy()) << "the client's abort ended the server's transfer";
  EXPECT_EQ(buffer, Bytes(12, 0xEE)) << "the size indication was refused before any byte arrived";

  // A server that does not indicate the size: the segment that would overflow is refused.
  client.cancel();
  to_server.clear();
  ASSERT_TRUE(client.upload_bytes(domain_index, 0, std::span<std::uint8_t>{buffer}.first(8), now_us, to_server));
  CanFrame unsized = encode_sdo_upload_segmented_response(node, domain_index, 0, 0);
  unsized.data[0] = 0x40;  // e = 0, s = 0
  ASSERT_TRUE(client.on_frame(unsized, now_us, to_server));
  const std::uint8_t seven[7] = {1, 2, 3, 4, 5, 6, 7};
  ASSERT_TRUE(client.on_frame(encode_sdo_upload_segment(node, false, seven, false), now_us, to_server));
  ASSERT_TRUE(client.on_frame(encode_sdo_upload_segment(node, true, seven, true), now_us, to_server));
  EXPECT_EQ(client.result().abort, SdoAbort::length_too_high);
  EXPECT_EQ(Bytes(buffer.begin() + 7, buffer.end()), (Bytes{0xEE, 0xEE, 0xEE, 0xEE, 0xEE}));
}

TEST_F(SdoSegmented, ServerWithoutADownloadBufferRefusesSegmentedStringDownloads) {
  SdoServer bare{node, od, server_timeout_us};
  FrameBuffer<2> out;
  ASSERT_TRUE(bare.on_frame(encode_sdo_download_segmented_request(node, label_index, 0, 10), now_us, out));
  EXPECT_EQ(test::bytes_of(out[0]), (Bytes{0x80, 0x02, 0x21, 0x00, 0x05, 0x00, 0x04, 0x05}));
  out.clear();
  ASSERT_TRUE(bare.on_frame(encode_sdo_download_request(node, label_index, 0, 0x41, 1), now_us, out));
  EXPECT_EQ(test::bytes_of(out[0])[0], 0x60) << "expedited downloads need no buffer";
  EXPECT_EQ(view_of(label.view()), text("A"));
}

// ---- Timeouts ----

TEST_F(SdoSegmented, ServerDropsATransferWhoseClientWentSilent) {
  now_us = 1'000;
  EXPECT_EQ(ask(encode_sdo_upload_request(node, name_index, 0))[0], 0x41);
  now_us = 15'000;
  EXPECT_EQ(ask(raw({0x60, 0, 0, 0, 0, 0, 0, 0}))[0], 0x00) << "in time: the deadline moves on";
  FrameBuffer<2> out;
  server.poll(15'000 + server_timeout_us - 1, out);
  EXPECT_TRUE(out.empty());
  EXPECT_TRUE(server.busy());
  server.poll(15'000 + server_timeout_us, out);
  ASSERT_EQ(out.size(), 1U);
  EXPECT_EQ(test::bytes_of(out[0]), (Bytes{0x80, 0x01, 0x21, 0x00, 0x00, 0x00, 0x04, 0x05}));
  EXPECT_FALSE(server.busy());
  EXPECT_EQ(server.timeouts(), 1U);
  now_us = 40'000;
  EXPECT_EQ(ask(encode_sdo_upload_request(node, name_index, 0))[0], 0x41) << "the next request works";
}

TEST_F(SdoSegmented, ServerThatWasNotPolledTimesOutBeforeTheLateFrame) {
  label.assign("old");
  EXPECT_EQ(ask(encode_sdo_download_segmented_request(node, label_index, 0, 10))[0], 0x60);
  now_us = server_timeout_us;
  FrameBuffer<4> out;
  ASSERT_TRUE(server.on_frame(raw({0x00, 1, 2, 3, 4, 5, 6, 7}), now_us, out));
  ASSERT_EQ(out.size(), 2U);
  EXPECT_EQ(test::bytes_of(out[0]), (Bytes{0x80, 0x02, 0x21, 0x00, 0x00, 0x00, 0x04, 0x05})) << "the timeout";
  EXPECT_EQ(test::bytes_of(out[1]), (Bytes{0x80, 0x00, 0x00, 0x00, 0x01, 0x00, 0x04, 0x05}))
      << "then the late segment, which belongs to no transfer";
  EXPECT_EQ(view_of(label.view()), text("old"));
}

TEST_F(SdoSegmented, ClientTimesOutMidTransferAndTheTimeoutRestartsWithEachSegment) {
  const Bytes data = pattern(100);
  ASSERT_TRUE(client.download_bytes(domain_index, 0, data, now_us, to_server));
  // Every frame is delivered 15 ms after it was sent (within both timeouts): eight round
  // trips take 120 ms, more than the client's 50 ms, and nothing times out.
  for (int i = 0; i < 8; ++i) {
    now_us += 15'000;
    client.poll(now_us, to_server);
    ASSERT_TRUE(client.busy());
    const std::vector<CanFrame> requests{to_server.frames().begin(), to_server.frames().end()};
    to_server.clear();
    for (const CanFrame& f : requests) {
      ASSERT_TRUE(server.on_frame(f, now_us, to_client));
    }
    const std::vector<CanFrame> answers{to_client.frames().begin(), to_client.frames().end()};
    to_client.clear();
    for (const CanFrame& f : answers) {
      ASSERT_TRUE(client.on_frame(f, now_us, to_server));
    }
  }
  ASSERT_TRUE(client.busy());
  ASSERT_EQ(to_server.size(), 1U);  // the eighth segment, which the server never gets
  to_server.clear();
  client.poll(now_us + client_timeout_us - 1, to_server);
  EXPECT_TRUE(client.busy());
  client.poll(now_us + client_timeout_us, to_server);
  EXPECT_EQ(client.status(), SdoClientStatus::timed_out);
  ASSERT_EQ(to_server.size(), 1U);
  EXPECT_EQ(test::bytes_of(to_server[0]), (Bytes{0x80, 0x00, 0x21, 0x00, 0x00, 0x00, 0x04, 0x05}));
  // The server, 20 ms after its last answer, had given up as well: its own timeout abort goes
  // out first, and the client's abort gets no answer.
  ASSERT_TRUE(server.on_frame(to_server[0], now_us + client_timeout_us, to_client));
  ASSERT_EQ(to_client.size(), 1U);
  EXPECT_EQ(test::bytes_of(to_client[0]), (Bytes{0x80, 0x00, 0x21, 0x00, 0x00, 0x00, 0x04, 0x05}));
  EXPECT_FALSE(server.busy());
  EXPECT_EQ(domain.view().size(), 0U) << "an aborted download stores nothing";
}

// ---- Unexpected commands ----

TEST_F(SdoSegmented, BlockTransferIsAnsweredWithAbort05040001) {
  // Block download initiate (ccs 6, cc 1, s 1, size 100) and block upload initiate (ccs 5).
  EXPECT_EQ(ask(raw({0xC6, 0x00, 0x21, 0x00, 100, 0, 0, 0})), (Bytes{0x80, 0x00, 0x21, 0x00, 0x01, 0x00, 0x04, 0x05}));
  EXPECT_EQ(ask(raw({0xA4, 0x00, 0x21, 0x00, 0x7F, 0x00, 0, 0})), (Bytes{0x80, 0x00, 0x21, 0x00, 0x01, 0x00, 0x04, 0x05}));
  EXPECT_EQ(ask(raw({0xE0, 0x00, 0x21, 0x00, 0, 0, 0, 0})), (Bytes{0x80, 0x00, 0x21, 0x00, 0x01, 0x00, 0x04, 0x05}))
      << "command specifier 7 exists in no service";
}

TEST_F(SdoSegmented, SegmentsWithoutATransferAreAnsweredWithAbort05040001) {
  EXPECT_EQ(ask(raw({0x60, 0, 0, 0, 0, 0, 0, 0})), (Bytes{0x80, 0, 0, 0, 0x01, 0x00, 0x04, 0x05}));
  EXPECT_EQ(ask(raw({0x01, 1, 2, 3, 4, 5, 6, 7})), (Bytes{0x80, 0, 0, 0, 0x01, 0x00, 0x04, 0x05}));
}

TEST_F(SdoSegmented, NewInitiateDuringATransferAbortsTheRunningOneThenWorks) {
  EXPECT_EQ(ask(encode_sdo_upload_request(node, name_index, 0))[0], 0x41);
  EXPECT_EQ(ask(encode_sdo_upload_request(node, word_index, 0)), (Bytes{0x80, 0x01, 0x21, 0x00, 0x01, 0x00, 0x04, 0x05}))
      << "the running transfer (0x2101) is aborted with 0x05040001";
  EXPECT_FALSE(server.busy());
  EXPECT_EQ(ask(encode_sdo_upload_request(node, word_index, 0))[0], 0x43) << "repeated, it is served";
}

TEST_F(SdoSegmented, ClientAbortEndsTheServersTransferSilently) {
  EXPECT_EQ(ask(encode_sdo_download_segmented_request(node, domain_index, 0, 30))[0], 0x60);
  FrameBuffer<2> out;
  ASSERT_TRUE(server.on_frame(encode_sdo_abort(node, true, domain_index, 0, SdoAbort::general_error), now_us, out));
  EXPECT_TRUE(out.empty());
  EXPECT_FALSE(server.busy());
}

}  // namespace
}  // namespace settle::hal::canopen
