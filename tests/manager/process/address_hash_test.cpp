// SPDX-License-Identifier: GPL-2.0-or-later
// The session index records the keyed hash of the participant's address that opened /start, the same hash
// sim_rfb writes in events.jsonl: the address a trusted proxy names in X-Forwarded-For (whole, an IPv6 one too,
// not the /64 the limits count), else the peer.
#include <catch2/catch.hpp>

#include <sqlite3.h>

#include <cstdlib>
#include <string>

#include "manager_process.hpp"
#include "record/digest.hpp"

using rfbsim::test::ManagerUnderTest;
using rfbsim::test::TempDir;
using rfbsim::test::token_from_redirect;

namespace {

constexpr const char* kAddressKey = "address-hash-key-for-the-test";

// The address_hash column of the session with `token`, read with a connection of our own ("?" when no row).
std::string address_hash_of(const std::filesystem::path& data_dir, const std::string& token) {
  sqlite3* db = nullptr;
  const std::string path = (data_dir / "sessions.db").string();
  REQUIRE(sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK);
  sqlite3_stmt* stmt = nullptr;
  REQUIRE(sqlite3_prepare_v2(db, "SELECT address_hash FROM sessions WHERE token = ?", -1, &stmt, nullptr) ==
          SQLITE_OK);
  sqlite3_bind_text(stmt, 1, token.c_str(), -1, SQLITE_TRANSIENT);
  std::string hash = "?";
  if (sqlite3_step(stmt) == SQLITE_ROW) hash = reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0));
  sqlite3_finalize(stmt);
  sqlite3_close(db);
  return hash;
}

}  // namespace

TEST_CASE("the index records the hash of the participant's address as a trusted proxy names it", "[manager]") {
  TempDir data;
  ::setenv("RFBSIM_ADDRESS_KEY", kAddressKey, 1);  // inherited by the manager
  // rfbsim_minimal as the session: only the row written before the redirect matters here.
  ManagerUnderTest manager(
      data.path(), rfbsim::test::without_abuse_limits({"--session-kind", "rfb", "--session-command", RFBSIM_MINIMAL,
                                                       "--session-arg", "{port}", "--scenarios", "demo",
                                                       "--trusted-proxies", "127.0.0.1"}));
  ::unsetenv("RFBSIM_ADDRESS_KEY");
  const auto start = [&](const std::string& uid, const std::string& forwarded_for) {
    if (forwarded_for.empty()) return token_from_redirect(manager.get("/start?uid=" + uid));
    return token_from_redirect(manager.get("/start?uid=" + uid, {{"X-Forwarded-For", forwarded_for}}));
  };

  const std::string forwarded = start("xff-1", "203.0.113.7");
  REQUIRE(forwarded.size() == 32);
  CHECK(address_hash_of(data.path(), forwarded) == rfbsim::sim::hash_address(kAddressKey, "203.0.113.7"));

  // An IPv6 participant is hashed whole: the /64 is only what the limits count.
  const std::string six = start("xff-2", "2001:db8:1:2::7");
  REQUIRE(six.size() == 32);
  CHECK(address_hash_of(data.path(), six) == rfbsim::sim::hash_address(kAddressKey, "2001:db8:1:2::7"));

  // Without the header the peer itself is the participant.
  const std::string direct = start("direct-1", "");
  REQUIRE(direct.size() == 32);
  CHECK(address_hash_of(data.path(), direct) == rfbsim::sim::hash_address(kAddressKey, "127.0.0.1"));
  CHECK(address_hash_of(data.path(), direct).size() == 16);
}
