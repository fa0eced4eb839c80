// The only place JS meets C++: embind registration of NativeClient (native_client.hpp) and of the
// object path parser (object_path_js.hpp). Names are the JS layer's (robotraconteur.mjs, proxy.mjs,
// object_path.mjs).
#include <emscripten/bind.h>

#include "wasm-client/src/native_client.hpp"
#include "wasm-client/src/object_path_js.hpp"

EMSCRIPTEN_BINDINGS(robotraconteur) {
    using rr::wasm::NativeClient;
    emscripten::class_<NativeClient>("NativeClient")
        .constructor<emscripten::val>()
        .function("setHandlers", &NativeClient::set_handlers)
        .function("feed", &NativeClient::feed)
        .function("takeOutput", &NativeClient::take_output)
        .function("nextDeadline", &NativeClient::next_deadline)
        .function("onTimer", &NativeClient::on_timer)
        .function("transportClosed", &NativeClient::transport_closed)
        .function("disconnect", &NativeClient::disconnect)
        .function("isConnected", &NativeClient::is_connected)
        .function("isClosed", &NativeClient::is_closed)
        .function("info", &NativeClient::info)
        .function("describe", &NativeClient::describe)
        .function("propertyGet", &NativeClient::property_get)
        .function("propertySet", &NativeClient::property_set)
        .function("call", &NativeClient::call)
        .function("callGenerator", &NativeClient::call_generator)
        .function("generatorNext", &NativeClient::generator_next)
        .function("generatorClose", &NativeClient::generator_close)
        .function("objref", &NativeClient::objref)
        .function("subscribeEvent", &NativeClient::subscribe_event)
        .function("unsubscribeEvent", &NativeClient::unsubscribe_event)
        .function("setCallback", &NativeClient::set_callback)
        .function("callbackReply", &NativeClient::callback_reply)
        .function("pipeConnect", &NativeClient::pipe_connect)
        .function("pipeSetHandlers", &NativeClient::pipe_set_handlers)
        .function("pipeSend", &NativeClient::pipe_send)
        .function("pipeReceive", &NativeClient::pipe_receive)
        .function("pipeClose", &NativeClient::pipe_close)
        .function("wireConnect", &NativeClient::wire_connect)
        .function("wireSetHandlers", &NativeClient::wire_set_handlers)
        .function("wireInValue", &NativeClient::wire_in_value)
        .function("wireOutValue", &NativeClient::wire_out_value)
        .function("wireSetOutValue", &NativeClient::wire_set_out_value)
        .function("wireSetLifespans", &NativeClient::wire_set_lifespans)
        .function("wireClose", &NativeClient::wire_close)
        .function("wirePeek", &NativeClient::wire_peek)
        .function("wirePoke", &NativeClient::wire_poke)
        .function("memoryParam", &NativeClient::memory_param)
        .function("memoryRead", &NativeClient::memory_read)
        .function("memoryWrite", &NativeClient::memory_write)
        .function("monitor", &NativeClient::monitor);
    emscripten::function("parseObjectPath", &rr::wasm::parse_object_path_js);
}
