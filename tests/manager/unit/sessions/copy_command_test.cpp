// SPDX-License-Identifier: GPL-2.0-or-later
// The after-session command's placeholders (one pass, one argument each, unknown names refused) and its retry
// schedule (5 s doubling up to 5 min).
#include <catch2/catch.hpp>

#include "config/config.hpp"
#include "sessions/copy_command.hpp"

using rfbsim::manager::copy_backoff;
using rfbsim::manager::copy_command_problem;
using rfbsim::manager::CopyPlaceholders;
using rfbsim::manager::substitute_copy_command;
using Args = std::vector<std::string>;

namespace {

CopyPlaceholders sample() {
  return {"/data/sessions/12-p-01", "12-p-01", "p-01", "h2", "12"};
}

}  // namespace

TEST_CASE("every placeholder is replaced inside its own argument, the rest kept as written") {
  const Args command = {"rsync", "-a", "{folder}/", "store.example.org:/study/{host}/{folder_name}/",
                        "--log={uid}-{session_id}.txt", "{folder}{folder}"};
  CHECK(substitute_copy_command(command, sample()) ==
        Args{"rsync", "-a", "/data/sessions/12-p-01/", "store.example.org:/study/h2/12-p-01/", "--log=p-01-12.txt",
             "/data/sessions/12-p-01/data/sessions/12-p-01"});
}

TEST_CASE("a value is never read again for placeholders, and a value with spaces stays one argument") {
  CopyPlaceholders values = sample();
  values.folder = "/data/a {uid} b";
  CHECK(substitute_copy_command({"cp", "-r", "{folder}", "/x"}, values) == Args{"cp", "-r", "/data/a {uid} b", "/x"});
}

TEST_CASE("braces that are not a placeholder are the program's own text") {
  const Args command = {"sh", "-c", "echo ${HOME} {} {a,b} {Folder} {", "{folder"};
  CHECK(copy_command_problem({"sh", "-c", "echo ${HOME} {} {a,b} {Folder} {", "{folder"}) == "");
  CHECK(substitute_copy_command(command, sample()) == command);
}

TEST_CASE("an unknown placeholder or an empty program is refused with the known names") {
  CHECK(copy_command_problem({"rsync", "{folder}", "store:/{dir}/x"}) ==
        "after_session_command: unknown placeholder {dir} in 'store:/{dir}/x' (known: {folder} {folder_name} {uid} "
        "{host} {session_id})");
  CHECK(copy_command_problem({"", "{folder}"}) == "after_session_command: the program (its first item) is empty");
  CHECK(copy_command_problem({}) == "");  // no copy
  CHECK(copy_command_problem({"rclone", "copy", "{folder}", "s3:study/{host}/{folder_name}"}) == "");
}

TEST_CASE("the backoff starts at 5 s, doubles, and stops at 5 min") {
  using std::chrono::seconds;
  CHECK(copy_backoff(0) == seconds(0));
  CHECK(copy_backoff(1) == seconds(5));
  CHECK(copy_backoff(2) == seconds(10));
  CHECK(copy_backoff(3) == seconds(20));
  CHECK(copy_backoff(4) == seconds(40));
  CHECK(copy_backoff(5) == seconds(80));
  CHECK(copy_backoff(6) == seconds(160));
  CHECK(copy_backoff(7) == seconds(300));
  CHECK(copy_backoff(8) == seconds(300));
  CHECK(copy_backoff(1000) == seconds(300));
}

TEST_CASE("after_session_command is one flag per argument, commas included, and its keys are checked") {
  using rfbsim::manager::parse_manager_args;
  const auto outcome = parse_manager_args({"--after-session-command", "rclone", "--after-session-command", "copy",
                                           "--after-session-command", "{folder}", "--after-session-command",
                                           "s3:a,b/{host}/{folder_name}", "--after-session-retries", "2",
                                           "--after-session-timeout-s", "90"});
  REQUIRE(outcome.error == "");
  CHECK(outcome.config.after_session_command == Args{"rclone", "copy", "{folder}", "s3:a,b/{host}/{folder_name}"});
  CHECK(outcome.config.after_session_retries == 2);
  CHECK(outcome.config.after_session_timeout == std::chrono::seconds(90));
  // The defaults: no copy; five more tries; ten minutes a try.
  const auto defaults = parse_manager_args({});
  CHECK(defaults.config.after_session_command.empty());
  CHECK(defaults.config.after_session_retries == 5);
  CHECK(defaults.config.after_session_timeout == std::chrono::seconds(600));
  CHECK(parse_manager_args({"--after-session-command", "cp", "--after-session-command", "{dir}"}).error ==
        "after_session_command: unknown placeholder {dir} in '{dir}' (known: {folder} {folder_name} {uid} {host} "
        "{session_id})");
  CHECK(parse_manager_args({"--after-session-retries", "-1"}).error ==
        "--after-session-retries '-1': expected an integer 0..100");
  CHECK(parse_manager_args({"--after-session-timeout-s", "0"}).error ==
        "--after-session-timeout-s '0': expected whole seconds 1..604800");
}

TEST_CASE("a placeholder other than {folder} may not begin an argument, nor any the program") {
  // A uid may begin with '-': as an argument of its own it would be an option ("-etouch" to rsync).
  CHECK(copy_command_problem({"rsync", "-a", "{folder}/", "{uid}"}).find("begins with {uid}") != std::string::npos);
  CHECK(copy_command_problem({"cp", "-r", "{folder}", "{host}/{folder_name}"}).find("begins with {host}") !=
        std::string::npos);
  CHECK(copy_command_problem({"{folder}/copy.sh"}).find("the program must be fixed") != std::string::npos);
  CHECK(copy_command_problem({"rsync", "-a", "{folder}/", "/store/{host}/{uid}"}) == "");
}
