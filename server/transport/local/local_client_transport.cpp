#include "server/transport/local/local_client_transport.hpp"

#include <boost/asio/post.hpp>

#include "server/transport/local/local_connector.hpp"

namespace rr::server::local {

namespace asio = boost::asio;
using unix_socket = asio::local::stream_protocol;

client::ClientTransport make_local_client_transport(std::function<NodeDirectories()> dirs) {
    return [dirs = std::move(dirs)](client::ClientStrand strand, const ConnectionUrl& url, const client::ClientOptions&,
                                    std::shared_ptr<ConnectionLogic> logic,
                                    std::function<void(Result<std::shared_ptr<PumpHandle>>)> done) {
        // The lookup reads a few small files: done on the strand, as the TCP connect completes there.
        asio::post(strand, [strand, url, dirs, logic = std::move(logic), done = std::move(done)]() mutable {
            auto socket = connect_local_socket(strand, url, dirs());
            if (!socket) return done(socket.take_error());
            auto pump = std::make_shared<StreamPump<unix_socket::socket>>(std::move(*socket), strand, logic);
            done(std::shared_ptr<PumpHandle>(pump));
            pump->start();
        });
    };
}

void local_client_transport(client::ClientStrand strand, const ConnectionUrl& url, const client::ClientOptions& options,
                            std::shared_ptr<ConnectionLogic> logic,
                            std::function<void(Result<std::shared_ptr<PumpHandle>>)> done) {
    static const client::ClientTransport transport = make_local_client_transport(default_node_directories);
    transport(std::move(strand), url, options, std::move(logic), std::move(done));
}

}  // namespace rr::server::local
