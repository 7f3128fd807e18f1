// The ground's side of command security: signing with the key file, verifying the flight's
// acknowledgements and events against an independently computed authenticator (fsw/auth), and the
// refusals (no key, a too-open key file).
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cstring>

#include "fsw/auth/auth.hpp"
#include "fsw/auth/key_file.hpp"
#include "ground/cli/ground_auth.hpp"
#include "test_util.hpp"
#include "rocksteady/param_table_t.hpp"
#include "wire/codec.hpp"

namespace rocksteady::ground::cli {
namespace {

namespace auth = rocksteady::fsw::auth;

struct Keyed {
  test::TempDir dir;
  std::string path = dir.file("key");
  auth::KeySet keys;
  Keyed() {
    EXPECT_EQ(auth::generate_key_file(path, 2), "");
    EXPECT_EQ(auth::load_key_file(path, keys), "");
    AuthOptions o;
    o.key_file = path;
    EXPECT_EQ(configure_auth(o), "");
  }
  ~Keyed() { reset_auth(); }
};

TEST(GroundAuth, SignedCommandVerifiesWithTheFlightsCanonicalEncoding) {
  Keyed k;
  auto m = wire::make<rocksteady::ground_cmd_t>();
  m.seq = 1234;
  m.sender_id = 2;
  m.opcode = 1;
  m.nargs = 1;
  m.args[0] = 4.0;
  m.args[5] = 9.0;  // garbage in an unused slot: zeroed (the decoder insists on it)
  authenticate(m);
  EXPECT_EQ(m.key_id, 1);
  EXPECT_EQ(m.args[5], 0.0);
  fsw::GroundCommand c;
  c.seq = 1234;
  c.source = 2;
  c.opcode = 1;
  c.arg_count = 1;
  c.args[0] = 4.0;
  c.key_id = 1;
  auth::MacBytes expect;
  auth::mac_command(c, k.keys.find(1)->key, expect);
  EXPECT_EQ(std::memcmp(expect.data(), m.mac, expect.size()), 0);
}

TEST(GroundAuth, AcksAndEventsAreAuthenticOnlyWithTheFlightsAuthenticator) {
  Keyed k;
  auto e = wire::make<rocksteady::event_t>();
  e.t = 5.0;
  e.seq = 7;
  e.id = 120;
  e.arg0 = 3;
  e.text = "uplink 3 complete";
  EXPECT_EQ(verify_event(e), AckAuth::kForged);  // unsigned
  auth::EventFields f;
  f.t = e.t;
  f.seq = e.seq;
  f.id = e.id;
  f.arg0 = e.arg0;
  f.key_id = 2;
  f.text = e.text.c_str();
  f.text_len = e.text.size();
  auth::MacBytes mac;
  auth::mac_event(f, k.keys.find(2)->key, mac);
  e.key_id = 2;
  std::memcpy(e.mac, mac.data(), mac.size());
  EXPECT_EQ(verify_event(e), AckAuth::kAuthentic);
  e.arg0 = 4;
  EXPECT_EQ(verify_event(e), AckAuth::kForged);

  auto a = wire::make<rocksteady::cmd_ack_t>();
  a.seq = 99;
  a.accepted = 1;
  a.text = "accepted";
  EXPECT_EQ(verify_ack(a), AckAuth::kForged);
  a.key_id = 7;  // unknown key id
  EXPECT_EQ(verify_ack(a), AckAuth::kForged);
}

// RS_PARAMS: the read-back is believed only with the flight's authenticator over every field
// (computed here with the flight's canonical encoding, fsw/auth mac_params); any changed value,
// counter, count or key id, an unknown key, a zero MAC, or a dump number the flight cannot have
// sent (above 32 bits) is forged. Lab mode shows it as unauthenticated.
TEST(GroundAuth, ParameterReadBackIsAuthenticOnlyWithTheFlightsAuthenticator) {
  Keyed k;
  fsw::ParamDump d;
  d.t = 812.5;
  d.seq = 3;
  d.count = 2;
  d.value_count[0] = 6;
  d.value_count[1] = 1;
  for (int v = 0; v < 6; ++v) d.values[0][static_cast<std::size_t>(v)] = 1e4 * (v + 1);
  d.values[1][0] = 0.25;
  auth::MacBytes mac;
  auth::mac_params(d, 2, k.keys.find(2)->key, mac);
  auto m = wire::make<rocksteady::param_table_t>();
  m.t = d.t;
  m.dump_seq = d.seq;
  m.count = d.count;
  for (int i = 0; i < fsw::kMaxDumpParams; ++i) {
    m.value_count[i] = d.value_count[static_cast<std::size_t>(i)];
    for (int v = 0; v < fsw::kMaxParamValues; ++v) {
      m.values[i][v] = d.values[static_cast<std::size_t>(i)][static_cast<std::size_t>(v)];
    }
  }
  m.key_id = 2;
  std::memcpy(m.mac, mac.data(), mac.size());
  ASSERT_EQ(verify_params(m), AckAuth::kAuthentic);

  const auto forged_after = [&](auto change) {
    auto x = m;
    change(x);
    return verify_params(x) == AckAuth::kForged;
  };
  EXPECT_TRUE(forged_after([](auto& x) { x.values[0][0] = 2e4; }));
  EXPECT_TRUE(forged_after([](auto& x) { x.values[31][5] = 1.0; }));  // an unused slot
  EXPECT_TRUE(forged_after([](auto& x) { x.value_count[1] = 2; }));
  EXPECT_TRUE(forged_after([](auto& x) { x.count = 3; }));
  EXPECT_TRUE(forged_after([](auto& x) { x.t = 812.6; }));
  EXPECT_TRUE(forged_after([](auto& x) { x.dump_seq = 4; }));
  EXPECT_TRUE(forged_after([](auto& x) { x.dump_seq += std::int64_t{1} << 32; }));
  EXPECT_TRUE(forged_after([](auto& x) { x.key_id = 1; }));   // another known key
  EXPECT_TRUE(forged_after([](auto& x) { x.key_id = 9; }));   // unknown key
  EXPECT_TRUE(forged_after([](auto& x) { std::memset(x.mac, 0, sizeof x.mac); }));
  EXPECT_TRUE(forged_after([](auto& x) { x.mac[31] ^= 1; }));
  EXPECT_TRUE(forged_after([](auto& x) { x.count = -1; }));
  // An event's authenticator with the same key and the same leading numbers never verifies as a
  // table (the channel and message kind are inside the MAC).
  {
    auth::EventFields f;
    f.t = d.t;
    f.seq = d.seq;
    f.key_id = 2;
    auth::MacBytes ev;
    auth::mac_event(f, k.keys.find(2)->key, ev);
    EXPECT_TRUE(forged_after([&](auto& x) { std::memcpy(x.mac, ev.data(), ev.size()); }));
  }
  reset_auth();
  AuthOptions lab;
  lab.lab = true;
  ASSERT_EQ(configure_auth(lab), "");
  EXPECT_EQ(verify_params(m), AckAuth::kLabMode);
}

TEST(GroundAuth, NoKeyOrATooOpenKeyFileIsRefused) {
  reset_auth();
  auto m = wire::make<rocksteady::ground_cmd_t>();
  EXPECT_THROW(authenticate(m), std::runtime_error);
  test::TempDir dir;
  const std::string p = dir.file("key");
  ASSERT_EQ(auth::generate_key_file(p, 1), "");
  chmod(p.c_str(), 0644);
  AuthOptions o;
  o.key_file = p;
  EXPECT_NE(configure_auth(o).find("too open"), std::string::npos);
  EXPECT_FALSE(auth_configured());
  o = AuthOptions{};
  o.lab = true;
  EXPECT_EQ(configure_auth(o), "");
  EXPECT_TRUE(auth_lab_mode());
  authenticate(m);
  EXPECT_EQ(m.key_id, 0);
  reset_auth();
}

}  // namespace
}  // namespace rocksteady::ground::cli
