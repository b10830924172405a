// The package's layer on Boost.Program_options (src/tools/cli_arguments.hpp): what every program's
// command line accepts and refuses, its help and its exit convention.
#include "cli_arguments.hpp"

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace {

namespace po = norm2tex::cli::po;
using norm2tex::cli::Program;
using norm2tex::cli::UsageError;

Program makeProgram() {
  Program program("norm2tex_example", "norm2tex_example MODE [FRAMES] -o OUT [--offset M]",
                  "Does an example. It takes a mode and a number of frames.");
  program.positional("MODE", 1, po::value<std::string>());
  program.positional("FRAMES", 1, po::value<int>());
  program.add()                                                                    //
      ("output,o", po::value<std::string>()->value_name("OUT"), "Where it goes.")  //
      ("offset", po::value<double>()->value_name("M"), "An offset, metres.")       //
      ("seed", po::value<std::int64_t>()->value_name("S"), "A seed.")              //
      ("scene", po::value<std::vector<std::string>>()->composing()->value_name("S.yaml"),
       "A scene, repeatable.")  //
      ("quiet", po::bool_switch(), "Print nothing.");
  return program;
}

po::variables_map parse(std::initializer_list<const char*> arguments) {
  std::vector<const char*> argv{"norm2tex_example"};
  argv.insert(argv.end(), arguments);
  return makeProgram().parse(static_cast<int>(argv.size()), argv.data());
}

/// The UsageError's message for `arguments`, or "" when they parse.
std::string refusal(std::initializer_list<const char*> arguments) {
  try {
    parse(arguments);
  } catch (const UsageError& e) {
    return e.what();
  }
  return "";
}

TEST(CliArguments, ValuesTypesAndPositionals) {
  const po::variables_map args =
      parse({"real_time", "60", "-o", "out.csv", "--offset=-0.002", "--seed", "-3", "--scene",
             "a.yaml", "--scene", "b.yaml", "--quiet"});
  EXPECT_EQ(args["MODE"].as<std::string>(), "real_time");
  EXPECT_EQ(args["FRAMES"].as<int>(), 60);
  EXPECT_EQ(args["output"].as<std::string>(), "out.csv");
  EXPECT_EQ(args["offset"].as<double>(), -0.002);
  EXPECT_EQ(args["seed"].as<std::int64_t>(), -3);
  EXPECT_EQ(args["scene"].as<std::vector<std::string>>(),
            (std::vector<std::string>{"a.yaml", "b.yaml"}));
  EXPECT_TRUE(args["quiet"].as<bool>());
  // A negative number is a value, also as the next argument; the long name works as -o does.
  EXPECT_EQ(parse({"x", "--offset", "-1e-3", "--output", "o"})["offset"].as<double>(), -1e-3);
  // Absent options: not counted; valueOr gives the fallback.
  const po::variables_map bare = parse({"x"});
  EXPECT_EQ(bare.count("FRAMES"), 0u);
  EXPECT_EQ(norm2tex::cli::valueOr(bare, "FRAMES", 600), 600);
  EXPECT_EQ(norm2tex::cli::valueOr(bare, "offset", 0.5), 0.5);
  EXPECT_FALSE(bare["quiet"].as<bool>());
}

TEST(CliArguments, MalformedNumbersAreRefusedNamingTheValue) {
  // What atoi took as 0, as 12 or as garbage: refused.
  EXPECT_NE(refusal({"x", "abc"}).find("'abc'"), std::string::npos);
  EXPECT_NE(refusal({"x", "12abc"}).find("'12abc'"), std::string::npos);
  EXPECT_NE(refusal({"x", "1.5"}).find("FRAMES"), std::string::npos);
  EXPECT_NE(refusal({"x", "99999999999"}).find("99999999999"), std::string::npos);
  EXPECT_NE(refusal({"x", "--offset", "lots"}).find("--offset"), std::string::npos);
  EXPECT_NE(refusal({"x", "--offset", ""}).find("--offset"), std::string::npos);
  EXPECT_NE(refusal({"x", "--seed", "1e3"}).find("--seed"), std::string::npos);
  // A positional argument is named as the synopsis names it, not as an option.
  EXPECT_EQ(refusal({"x", "abc"}).find("--FRAMES"), std::string::npos) << refusal({"x", "abc"});
}

TEST(CliArguments, NumbersMustBeFinite) {
  for (const char* text : {"nan", "inf", "-inf", "NaN", "infinity"}) {
    const std::string message = refusal({"x", "--offset", text});
    EXPECT_NE(message.find("--offset expects a finite number"), std::string::npos)
        << text << ": " << message;
  }
}

TEST(CliArguments, MistakesOnTheLineAreRefusedByName) {
  EXPECT_NE(refusal({"x", "--frobnicate"}).find("'--frobnicate'"), std::string::npos);
  EXPECT_NE(refusal({"x", "--offset"}).find("--offset"), std::string::npos) << "missing value";
  EXPECT_NE(refusal({"x", "-o"}).find("output"), std::string::npos) << "missing value";
  EXPECT_NE(refusal({"x", "--quiet=1"}).find("--quiet"), std::string::npos);
  EXPECT_NE(refusal({"x", "--offset", "1", "--offset", "2"}).find("more than once"),
            std::string::npos);
  // No abbreviations: --off is not --offset.
  EXPECT_NE(refusal({"x", "--off", "1"}).find("'--off'"), std::string::npos);
  // An argument beyond the declared positionals is named.
  EXPECT_NE(refusal({"x", "60", "extra"}).find("unexpected argument 'extra'"), std::string::npos);
}

TEST(CliArguments, HelpHasTheUsageADescriptionAndEveryOption) {
  const std::string help = makeProgram().help();
  EXPECT_EQ(help.rfind("usage: norm2tex_example MODE [FRAMES]", 0), 0u) << help;
  EXPECT_NE(help.find("\n\nDoes an example. It takes a mode and a number of frames.\n\n"),
            std::string::npos)
      << help;
  for (const char* option : {"-h [ --help ]", "-o [ --output ] OUT", "--offset M", "--seed S",
                             "--scene S.yaml", "--quiet", "Where it goes."}) {
    EXPECT_NE(help.find(option), std::string::npos) << option << "\n" << help;
  }
  EXPECT_EQ(help.find("--MODE"), std::string::npos) << "positionals are not listed as options";
}

int runMain(std::initializer_list<const char*> arguments,
            const std::function<int(int, char**)>& body) {
  std::vector<std::string> storage{"norm2tex_example"};
  storage.insert(storage.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& argument : storage) argv.push_back(argument.data());
  return makeProgram().main(static_cast<int>(argv.size()), argv.data(), body);
}

TEST(CliArguments, ExitConvention) {
  const Program program = makeProgram();
  bool ran = false;
  const auto parses = [&](int argc, char** argv) {
    ran = true;
    program.parse(argc, argv);
    return 0;
  };
  // --help anywhere: 0, and the body does not run (nor are the other arguments checked).
  testing::internal::CaptureStdout();
  EXPECT_EQ(runMain({"--frobnicate", "--help"}, parses), 0);
  EXPECT_EQ(testing::internal::GetCapturedStdout().rfind("usage: norm2tex_example", 0), 0u);
  EXPECT_FALSE(ran);
  // A usage error: 2, "NAME: error: ..." then the usage.
  testing::internal::CaptureStderr();
  EXPECT_EQ(runMain({"x", "12abc"}, parses), 2);
  const std::string usage_error = testing::internal::GetCapturedStderr();
  EXPECT_EQ(usage_error.rfind("norm2tex_example: error: ", 0), 0u) << usage_error;
  EXPECT_NE(usage_error.find("\nusage: norm2tex_example MODE"), std::string::npos) << usage_error;
  EXPECT_NE(usage_error.find("Run 'norm2tex_example --help' for every option."), std::string::npos)
      << usage_error;
  // Any other failure: 1, one line.
  testing::internal::CaptureStderr();
  EXPECT_EQ(runMain({}, [](int, char**) -> int { throw std::runtime_error("bad\ninput"); }), 1);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "norm2tex_example: error: bad input\n");
  EXPECT_EQ(runMain({}, [](int, char**) { return 3; }), 3);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
