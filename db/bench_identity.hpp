// A bench's identity as a sweep records it (schema v9): the bench's name and host and its
// devices' profiles with their versions, so sweeps from several benches in one lab store can be
// told apart and compared. docs/database.md "Bench identity".
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "db/error.hpp"
#include "db/types.hpp"
#include "drivers/json.hpp"

namespace synbench::db {

// A profile's version: "fnv1a64:" and 16 hex digits of its canonical JSON (keys sorted, no
// whitespace), so a comment's reflow does not change it and any register change does. A
// profile document with a string "version" member gives that instead.
std::string profile_version(const synbench::Json& profile_doc);

// The identity of the profile in `profile_file` for `device` ("synrm_drive", ...); errc::io with
// the reader's reason when the file cannot be read as JSON.
Result<DeviceIdentity> device_identity(std::string device, const std::filesystem::path& profile_file);

// The in-process twin's three devices: profile "synbench twin", version synbench's own.
std::vector<DeviceIdentity> twin_devices();

// `b` with its empty name and host filled in: host from gethostname(), name from the host.
BenchIdentity resolved(BenchIdentity b);

// The devices as stored (a JSON array of {device, profile, version}) and back; errc::bad_record
// for text that is not such an array.
std::string devices_json(const std::vector<DeviceIdentity>& devices);
Result<std::vector<DeviceIdentity>> parse_devices_json(std::string_view text);

}  // namespace synbench::db
