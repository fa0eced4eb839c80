// The named types fuzz_message_structured renders every element as (through the compiled JSON text
// plan and the general path), under names its mutator uses; gen_message_seeds writes a seed of them.
#pragma once

namespace rr::fuzz {

inline constexpr const char* kPlanRobdef = R"(service svc
stdver 0.10
enum E
    a = 1,
    b = 2
end
namedarray N
    field double x
    field double[2] y
end
pod P
    field int32 i
    field N n
    field uint8[2,2] m
end
struct S
    field string s
    field double[] d
    field P p
    field N[] ns
    field E e
    field S next
    field int32{list} l
    field string{string} m
    field P[]{int32} pm
    field double[*] md
end
struct W
    field varvalue any
    field P[*] grid
    field double x
end
)";

}  // namespace rr::fuzz
