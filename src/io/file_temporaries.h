// voxfield — the temporaries of FileTransaction: their names, the registry that signal handlers
// walk to remove them, and the sweep of stale ones left by dead processes.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <string_view>

namespace voxfield::detail {

// Name (not path) of a new temporary for the target file name `target_name`:
// ".NAME.vftmp.HOST.PID.N" (HOST: 8 hex digits naming this host), NAME shortened (at a UTF-8
// character boundary) so that the whole name fits in NAME_MAX bytes.
std::string temporary_name(std::string_view target_name);

// Whether `name` is exactly ".<anything>.vftmp.[<host>.]<pid>.<n>" (anything non-empty, host 8
// lowercase hex digits, pid and n decimal without leading zeros, pid > 0); sets `pid`, and
// `this_host` to whether it names this host (true without a host: the names of older versions).
bool parse_temporary_name(std::string_view name, pid_t& pid, bool& this_host);

// Unlinks, in `dir`, the regular files whose names parse_temporary_name accepts, written on this
// host by a process that is not alive. Best effort: errors are ignored (an unreadable directory
// is skipped). Another host's temporaries are never touched: its PIDs mean nothing here.
void sweep_stale_temporaries(const std::filesystem::path& dir);

// Lists `path` (made absolute) in the registry; returns its slot, or -1 when the registry is full
// or the path too long. Call before creating the file so that no signal can miss it.
int register_temporary(const std::filesystem::path& path);
// Removes slot `slot` (-1: nothing) from the registry, after the file was renamed or unlinked.
void unregister_temporary(int slot);

}  // namespace voxfield::detail
