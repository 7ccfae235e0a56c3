// The Foxglove WebSocket protocol's server side (pixyslam/foxglove/ws_protocol.h).
#include <gtest/gtest.h>

#include "pixyslam/foxglove/ws_protocol.h"

namespace pixyslam::foxglove {
namespace {

using Kind = ClientRequest::Kind;

TEST(WsProtocol, MessageDataFrameIsOpcodeIdTimeLittleEndianThenPayload) {
  const std::uint8_t payload[] = {0xaa, 0xbb};
  const std::vector<std::uint8_t> f = message_data_frame(0x01020304, 0x1122334455667788ULL, payload, 2);
  const std::vector<std::uint8_t> want = {0x01, 0x04, 0x03, 0x02, 0x01, 0x88, 0x77, 0x66, 0x55,
                                          0x44, 0x33, 0x22, 0x11, 0xaa, 0xbb};
  EXPECT_EQ(f, want);
}

TEST(WsProtocol, AdvertiseCarriesTheSchemaAsText) {
  const std::string text = advertise_json({{7, "pixyslam/odometry", "cdr", "pixyslam::msg::Odometry", "struct X {};", "omgidl"}});
  EXPECT_NE(text.find("\"op\":\"advertise\""), std::string::npos);
  EXPECT_NE(text.find("\"id\":7"), std::string::npos);
  EXPECT_NE(text.find("\"schema\":\"struct X {};\""), std::string::npos);
  EXPECT_NE(text.find("\"schemaEncoding\":\"omgidl\""), std::string::npos);
}

TEST(WsProtocol, ParsesSubscribeAndUnsubscribe) {
  const ClientRequest s = parse_client_request(R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":3},{"id":4294967295,"channelId":1}]})");
  ASSERT_EQ(s.kind, Kind::kSubscribe) << s.error;
  ASSERT_EQ(s.subscriptions.size(), 2u);
  EXPECT_EQ(s.subscriptions[1].first, 4294967295u);
  const ClientRequest u = parse_client_request(R"({"op":"unsubscribe","subscriptionIds":[5,6]})");
  ASSERT_EQ(u.kind, Kind::kUnsubscribe);
  EXPECT_EQ(u.subscription_ids, (std::vector<std::uint32_t>{5, 6}));
}

TEST(WsProtocol, MalformedRequestsAreErrorsThatSayWhy) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "not valid JSON"},
      {"{\"op\":", "not valid JSON"},
      {"[1]", "not a JSON object"},
      {"{}", "missing \"op\""},
      {R"({"op":5})", "missing \"op\""},
      {R"({"op":"subscribe"})", "not an array"},
      {R"({"op":"subscribe","subscriptions":[7]})", "not an object"},
      {R"({"op":"subscribe","subscriptions":[{"id":1}]})", "missing \"channelId\""},
      {R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":1}]})", "\"id\" is not an integer"},
      {R"({"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":1}]})", "\"id\" is not an integer"},
      {R"({"op":"subscribe","subscriptions":[{"id":1.5,"channelId":1}]})", "\"id\" is not an integer"},
      {R"({"op":"unsubscribe","subscriptionIds":["a"]})", "not an integer"},
      {R"({"op":"advertise","channels":[]})", "not supported"},
      {std::string("{\"op\":\"\xff\xfe\"}"), "not valid JSON"},  // not UTF-8
  };
  for (const auto& [text, why] : cases) {
    const ClientRequest r = parse_client_request(text);
    EXPECT_EQ(r.kind, Kind::kError) << text;
    EXPECT_NE(r.error.find(why), std::string::npos) << text << " -> " << r.error;
    EXPECT_NE(status_json(StatusLevel::kError, r.error).find("\"op\":\"status\""), std::string::npos);
  }
  std::string many = R"({"op":"subscribe","subscriptions":[)";
  for (int i = 0; i < 5; ++i) many += std::string(i ? "," : "") + "{\"id\":" + std::to_string(i) + ",\"channelId\":1}";
  EXPECT_EQ(parse_client_request(many + "]}", 4).kind, Kind::kError);
}

TEST(WsProtocol, SessionRefusesReusedIdsUnknownChannelsAndTooMany) {
  ClientSession session(3);
  const std::vector<std::uint32_t> channels = {1, 2};
  auto subscribe = [&](std::vector<std::pair<std::uint32_t, std::uint32_t>> s) {
    ClientRequest r;
    r.kind = Kind::kSubscribe;
    r.subscriptions = std::move(s);
    return session.apply(r, channels);
  };
  EXPECT_TRUE(subscribe({{10, 1}, {11, 1}}).empty());
  EXPECT_EQ(subscribe({{10, 2}}).size(), 1u);  // id in use
  EXPECT_EQ(subscribe({{12, 9}}).size(), 1u);  // not advertised
  EXPECT_TRUE(subscribe({{12, 2}}).empty());
  EXPECT_EQ(subscribe({{13, 2}}).size(), 1u);  // a fourth
  EXPECT_EQ(session.subscriptions_of(1), (std::vector<std::uint32_t>{10, 11}));
  ClientRequest u;
  u.kind = Kind::kUnsubscribe;
  u.subscription_ids = {11, 99};
  EXPECT_EQ(session.apply(u, channels).size(), 1u);  // 99 unknown, 11 removed
  EXPECT_EQ(session.subscriptions_of(1), (std::vector<std::uint32_t>{10}));
}

}  // namespace
}  // namespace pixyslam::foxglove
