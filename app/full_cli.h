#pragma once
// Every subcommand of lucent-full (the renderer's as well as the light ones), in one
// call: main.cpp runs it, and tests run it in-process (a technique registered by a test
// is then seen by `render`, `bench accuracy` and the rest).
namespace lucent::app {

int run_full_cli(int argc, char** argv);

}  // namespace lucent::app
