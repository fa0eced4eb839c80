// rr_local_probe: our rr+local rules from the command line, for the interop scripts.
//   rr_local_probe dirs          the node directories (server/transport/local/node_directories.hpp) of
//                                this process as one JSON object, keys as the official NodeDirectories
//   rr_local_probe lookup URL    finds and connects the socket an rr+local URL names
//                                (local_connector.hpp); prints {"ok": true, "socket": …, "entry": …}
//                                or {"ok": false, "error": …, "message": …}; exit 0 / 1
#include <iostream>
#include <string>

#include <boost/asio/io_context.hpp>

#include "server/transport/local/local_connector.hpp"
#include "server/transport/local/node_directories.hpp"

using namespace rr;
using namespace rr::server::local;

namespace {

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (unsigned char c : s) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += static_cast<char>(c);
        } else if (c < 0x20) {
            static const char* hex = "0123456789abcdef";
            out += "\\u00";
            out += hex[c >> 4];
            out += hex[c & 15];
        } else {
            out += static_cast<char>(c);
        }
    }
    return out + "\"";
}

}  // namespace

int main(int argc, char** argv) {
    std::string cmd = argc > 1 ? argv[1] : "";
    if (cmd == "dirs" && argc == 2) {
        auto d = default_node_directories();
        std::cout << "{\"system_cache_dir\": " << json_string(d.system_cache_dir)
                  << ", \"system_config_dir\": " << json_string(d.system_config_dir)
                  << ", \"system_data_dir\": " << json_string(d.system_data_dir)
                  << ", \"system_run_dir\": " << json_string(d.system_run_dir)
                  << ", \"system_state_dir\": " << json_string(d.system_state_dir)
                  << ", \"user_cache_dir\": " << json_string(d.user_cache_dir)
                  << ", \"user_config_dir\": " << json_string(d.user_config_dir)
                  << ", \"user_data_dir\": " << json_string(d.user_data_dir)
                  << ", \"user_run_dir\": " << json_string(d.user_run_dir)
                  << ", \"user_state_dir\": " << json_string(d.user_state_dir) << "}" << std::endl;
        return 0;
    }
    if (cmd == "lookup" && argc == 3) {
        auto url = parse_connection_url(argv[2]);
        if (!url) {
            std::cout << "{\"ok\": false, \"error\": " << json_string(std::string(error_name(url.error().type)))
                      << ", \"message\": " << json_string(url.error().message) << "}" << std::endl;
            return 1;
        }
        boost::asio::io_context io;
        FoundNode found;
        auto s = connect_local_socket(io.get_executor(), *url, default_node_directories(), &found);
        if (!s) {
            std::cout << "{\"ok\": false, \"error\": " << json_string(std::string(error_name(s.error().type)))
                      << ", \"message\": " << json_string(s.error().message) << "}" << std::endl;
            return 1;
        }
        std::cout << "{\"ok\": true, \"socket\": " << json_string(found.socket_path) << ", \"entry\": " << json_string(found.info_path)
                  << "}" << std::endl;
        return 0;
    }
    std::cerr << "usage: rr_local_probe dirs | rr_local_probe lookup URL" << std::endl;
    return 2;
}
