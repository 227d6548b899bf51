// TLS on the bridge, end to end with a self-signed certificate made for the test (openssl CLI):
// verification by CA file and by pinned fingerprint, refusals of a wrong pin, of an unverifiable
// server and of a plaintext client, and the bind policy.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "bridge_fixture.hpp"
#include "support/self_signed.hpp"

namespace edm::bridge::test {
namespace {

using namespace std::chrono_literals;

class Tls : public BridgeFixture {
 protected:
  void SetUp() override {
    cert_ = dir_.file("cert.pem");
    key_ = dir_.file("key.pem");
    fingerprint_ = edm::test::make_self_signed(key_, cert_, "edmplc-test");
    ASSERT_FALSE(fingerprint_.empty()) << "openssl could not make a certificate";
  }
  ServerOptions tls_options() {
    ServerOptions o;
    o.tls_cert = cert_;
    o.tls_key = key_;
    return o;
  }
  ClientOptions tls_client() {
    ClientOptions c = client_opts();
    c.tls.enabled = true;
    return c;
  }
  std::string cert_, key_, fingerprint_;
};

TEST_F(Tls, a_client_verifying_the_ca_file_is_served_over_tls) {
  start(tls_options());
  ClientOptions c = tls_client();
  c.tls.ca_file = cert_;
  EventSink sink;  // declared first: it must outlive the client's I/O thread
  Client client;
  ASSERT_EQ(client.connect(c), Role::kOperator);
  const Reply r = client.request("status");
  ASSERT_TRUE(r) << r.message;
  // Big replies and events cross TLS records intact.
  client.set_event_handler(sink.handler());
  ASSERT_TRUE(client.subscribe({"status"}, 100));
  EXPECT_EQ(sink.wait_for("status", 20).size(), 20u);
  EXPECT_TRUE(client.request("var.list"));
}

TEST_F(Tls, a_pinned_fingerprint_is_checked_whatever_its_spelling) {
  start(tls_options());
  ClientOptions c = tls_client();
  c.tls.fingerprint = fingerprint_;  // AB:CD:… as openssl prints it
  Client ok;
  EXPECT_EQ(ok.connect(c), Role::kOperator);
  c.tls.fingerprint = normalise_fingerprint(fingerprint_);
  Client ok2;
  EXPECT_EQ(ok2.connect(c), Role::kOperator);
  std::string wrong = normalise_fingerprint(fingerprint_);
  wrong[0] = wrong[0] == '0' ? '1' : '0';
  c.tls.fingerprint = wrong;
  Client bad;
  try {
    bad.connect(c);
    ADD_FAILURE() << "a wrong pin was accepted";
  } catch (const ClientError& e) {
    EXPECT_NE(std::string(e.what()).find("not the pinned one"), std::string::npos) << e.what();
  }
}

TEST_F(Tls, an_unverifiable_server_is_refused_by_the_client) {
  start(tls_options());
  // A CA that did not sign the server's certificate.
  const std::string other_key = dir_.file("other-key.pem");
  const std::string other = dir_.file("other.pem");
  ASSERT_FALSE(edm::test::make_self_signed(other_key, other, "other").empty());
  ClientOptions c = tls_client();
  c.tls.ca_file = other;
  Client client;
  EXPECT_THROW(client.connect(c), ClientError);
  ClientOptions none = tls_client();  // neither a CA nor a pin: nothing to verify against
  EXPECT_THROW(client.connect(none), ClientError);
}

TEST_F(Tls, a_plaintext_client_on_a_tls_port_is_refused_cleanly) {
  start(tls_options());
  Client plain;
  try {
    plain.connect(client_opts());
    ADD_FAILURE() << "plaintext was served on a TLS port";
  } catch (const ClientError& e) {
    ASSERT_TRUE(e.code().has_value()) << e.what();
    EXPECT_EQ(*e.code(), ErrorCode::kUnauthorized);
    EXPECT_NE(std::string(e.what()).find("this port speaks TLS"), std::string::npos) << e.what();
  }
  // And the server goes on serving TLS clients.
  ClientOptions c = tls_client();
  c.tls.ca_file = cert_;
  Client client;
  EXPECT_EQ(client.connect(c), Role::kOperator);
}

TEST(TlsPolicy, a_network_bind_needs_tls_or_a_loud_opt_out) {
  edm::test::TempDir dir{"edm-tls-policy"};
  ServerOptions o;
  o.bind = "0.0.0.0";
  o.token_file = dir.file("op.token");
  write_token(o.token_file, "operator-token-4f1c2a9b", 0600);
  try {
    validate_options(o);
    ADD_FAILURE() << "a network bind without TLS was accepted";
  } catch (const BridgeError& e) {
    EXPECT_NE(std::string(e.what()).find("insecure_plaintext"), std::string::npos) << e.what();
  }
  o.insecure_plaintext = true;
  EXPECT_NO_THROW(validate_options(o));
  o.insecure_plaintext = false;
  o.tls_cert = dir.file("missing.pem");
  o.tls_key = dir.file("missing-key.pem");
  EXPECT_THROW(validate_options(o), BridgeError) << "unreadable TLS files";
  o.tls_key.clear();
  EXPECT_THROW(validate_options(o), BridgeError) << "a cert without a key";
}

}  // namespace
}  // namespace edm::bridge::test
