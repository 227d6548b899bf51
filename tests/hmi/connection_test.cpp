// resolve_connection: flags over the environment, the token file over $EDM_TOKEN, bad ports and
// bad token files refused with a message naming them (hmi/connection.hpp).
#include "edm/hmi/connection.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>
#include <map>
#include <string>

#include "support/temp_dir.hpp"

namespace edm::hmi::test {
namespace {

// resolve_connection takes a plain function pointer: the fake environment is a global the
// fixture fills and clears.
std::map<std::string, std::string>& fake_env() {
  static std::map<std::string, std::string> env;
  return env;
}

ConnectionFlags flags(const std::string& host, const std::string& port,
                      const std::string& token_file) {
  ConnectionFlags f;
  f.host = host;
  f.port = port;
  f.token_file = token_file;
  return f;
}

const char* lookup(const char* name) {
  const auto it = fake_env().find(name);
  return it == fake_env().end() ? nullptr : it->second.c_str();
}

class ResolveConnection : public ::testing::Test {
 protected:
  void SetUp() override { fake_env().clear(); }
  void TearDown() override { fake_env().clear(); }

  std::string token_file(const std::string& name, const std::string& text) {
    const std::string path = dir_.file(name);
    std::ofstream(path) << text;
    ::chmod(path.c_str(), 0600);
    return path;
  }

  /// The SettingsError message of resolving `flags`, or "" when it resolved.
  static std::string error_of(const ConnectionFlags& flags) {
    try {
      (void)resolve_connection(flags, lookup);
      return "";
    } catch (const SettingsError& e) {
      return e.what();
    }
  }

  edm::test::TempDir dir_{"edm-hmi-conn"};
};

TEST_F(ResolveConnection, DefaultsWithoutFlagsOrEnvironment) {
  const ConnectionSettings s = resolve_connection({}, lookup);
  EXPECT_EQ(s.host, "127.0.0.1");
  EXPECT_EQ(s.port, 7730);
  EXPECT_EQ(s.token, "");
  EXPECT_EQ(s.token_source, "");
  // A null lookup is "no environment".
  EXPECT_EQ(resolve_connection({}, nullptr).port, 7730);
}

TEST_F(ResolveConnection, EnvironmentWhenNoFlags) {
  fake_env() = {{"EDM_HOST", "plc.local"}, {"EDM_PORT", "7801"}, {"EDM_TOKEN", "  tok-env \n"}};
  const ConnectionSettings s = resolve_connection({}, lookup);
  EXPECT_EQ(s.host, "plc.local");
  EXPECT_EQ(s.port, 7801);
  EXPECT_EQ(s.token, "tok-env");  // trimmed
  EXPECT_EQ(s.token_source, "$EDM_TOKEN");
}

TEST_F(ResolveConnection, FlagsWinOverEnvironment) {
  const std::string flag_file = token_file("flag.token", "tok-flag\nsecond line ignored\n");
  const std::string env_file = token_file("env.token", "tok-envfile\n");
  fake_env() = {{"EDM_HOST", "plc.local"},
                {"EDM_PORT", "7801"},
                {"EDM_TOKEN_FILE", env_file},
                {"EDM_TOKEN", "tok-env"}};
  const ConnectionSettings s = resolve_connection(flags("10.0.0.5", "7999", flag_file), lookup);
  EXPECT_EQ(s.host, "10.0.0.5");
  EXPECT_EQ(s.port, 7999);
  EXPECT_EQ(s.token, "tok-flag");
  EXPECT_EQ(s.token_source, "--token-file " + flag_file);
}

TEST_F(ResolveConnection, TokenFileFromEnvironmentWinsOverEdmToken) {
  const std::string env_file = token_file("env.token", "  tok-envfile  \r\n");
  fake_env() = {{"EDM_TOKEN_FILE", env_file}, {"EDM_TOKEN", "tok-env"}};
  const ConnectionSettings s = resolve_connection({}, lookup);
  EXPECT_EQ(s.token, "tok-envfile");
  EXPECT_EQ(s.token_source, "$EDM_TOKEN_FILE " + env_file);
}

TEST_F(ResolveConnection, EmptyEnvironmentValuesCountAsUnset) {
  fake_env() = {{"EDM_HOST", ""}, {"EDM_PORT", ""}, {"EDM_TOKEN_FILE", ""}, {"EDM_TOKEN", "t"}};
  const ConnectionSettings s = resolve_connection({}, lookup);
  EXPECT_EQ(s.host, "127.0.0.1");
  EXPECT_EQ(s.port, 7730);
  EXPECT_EQ(s.token, "t");
}

TEST_F(ResolveConnection, BadPortIsRefusedNamingWhereItCameFrom) {
  for (const std::string bad : {"0", "65536", "-1", "77x", "x", " 7730", "99999999999"}) {
    const std::string flag_error = error_of(flags("", bad, ""));
    EXPECT_NE(flag_error.find("--port: '" + bad + "'"), std::string::npos)
        << bad << ": " << flag_error;
    fake_env() = {{"EDM_PORT", bad}};
    const std::string env_error = error_of({});
    EXPECT_NE(env_error.find("$EDM_PORT: '" + bad + "'"), std::string::npos)
        << bad << ": " << env_error;
    fake_env().clear();
  }
  EXPECT_EQ(resolve_connection(flags("", "1", ""), lookup).port, 1);
  EXPECT_EQ(resolve_connection(flags("", "65535", ""), lookup).port, 65535);
}

TEST_F(ResolveConnection, BadPortInTheEnvironmentIsIgnoredWhenTheFlagIsGiven) {
  fake_env() = {{"EDM_PORT", "nonsense"}};
  EXPECT_EQ(resolve_connection(flags("", "7001", ""), lookup).port, 7001);
}

TEST_F(ResolveConnection, EmptyOrMissingTokenFileIsRefused) {
  const std::string empty = token_file("empty.token", "");
  const std::string blank = token_file("blank.token", "   \n\ntoken-on-line-3\n");
  const std::string missing = dir_.file("missing.token");
  for (const std::string& f : {empty, blank}) {
    const std::string e = error_of(flags("", "", f));
    EXPECT_NE(e.find("token file '" + f + "': empty first line"), std::string::npos) << e;
  }
  EXPECT_NE(error_of(flags("", "", missing)).find("token file '" + missing + "': cannot be read"),
            std::string::npos);
  // From the environment too, and a bad $EDM_TOKEN_FILE is not silently replaced by $EDM_TOKEN.
  fake_env() = {{"EDM_TOKEN_FILE", missing}, {"EDM_TOKEN", "tok-env"}};
  EXPECT_NE(error_of({}).find(missing), std::string::npos);
  EXPECT_THROW(read_token_file(empty), SettingsError);
  EXPECT_EQ(read_token_file(token_file("ok.token", "\tabc \n")), "abc");
}

TEST(ParsePort, NamesWhatInTheMessage) {
  EXPECT_EQ(parse_port("7730", "x"), 7730);
  try {
    (void)parse_port("70000", "bridge.port");
    FAIL() << "70000 accepted";
  } catch (const SettingsError& e) {
    EXPECT_STREQ(e.what(), "bridge.port: '70000' is not a port number (1..65535)");
  }
}

}  // namespace
}  // namespace edm::hmi::test
