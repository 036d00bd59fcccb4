// SPDX-License-Identifier: GPL-2.0-or-later
// Digests for session data: keyed hashes of network addresses, SHA-256 of the files a session was made from.
#pragma once

#include <filesystem>
#include <string>

namespace rfbsim::sim {

/// The hashing key: RFBSIM_ADDRESS_KEY from the environment when set (the study keeps it, so that equal
/// addresses hash alike across sessions), else 32 random bytes drawn for this process.
std::string address_hash_key();

/// The first 16 hex digits of HMAC-SHA256(key, address). An IPv4 address has only 2^32 values, so a plain
/// hash could be reversed by trying them all; the key stops that.
std::string hash_address(const std::string& key, const std::string& address);

/// The first 16 hex digits of HMAC-SHA256(key, "uid:" + uid): how a participant is named in another
/// participant's records (a watcher's yoked_to_uid_hash), never by the uid itself. Keyed like addresses, so that
/// a list of known uids cannot be tried against it; the prefix keeps a uid from hashing like an address.
std::string hash_uid(const std::string& key, const std::string& uid);

/// SHA-256 of a file's bytes as 64 hex digits. Throws std::runtime_error naming the file when it cannot
/// be read.
std::string sha256_file(const std::filesystem::path& file);

}  // namespace rfbsim::sim
