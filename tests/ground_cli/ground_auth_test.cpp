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
