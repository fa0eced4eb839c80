// libFuzzer target for the message codec (base/message): arbitrary bytes through the reader, the
// writer and the stream reader (the checks are in message_checks.hpp). Seeds:
// test/fuzz/seeds/fuzz_message_reader (made by gen_message_seeds); the shared vectors can be added as a
// second corpus directory:
//   build/fuzz/test/fuzz/fuzz_message_reader corpus/ ../shared/protocol/vectors
// fuzz_message_structured runs the same checks on inputs made by a structure-aware mutator.
#include "test/fuzz/message_checks.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    rr::fuzz::check_message_input(data, size);
    return 0;
}
