#include "server/transport/tls/tls_stream.hpp"

template class rr::server::StreamPump<rr::server::TlsStream>;

namespace rr::server {

bool serve_tls_stream(ConnectionSink& sink, TlsStream stream, const AcceptedStream& info, std::vector<std::byte> initial) {
    return serve_stream(sink, std::move(stream), info, std::move(initial));
}

void start_client_tls_stream(TlsStream stream, boost::asio::any_io_executor strand, std::shared_ptr<ConnectionLogic> logic,
                             const ConnectHandler& done) {
    start_client_stream(std::move(stream), std::move(strand), std::move(logic), done);
}

}  // namespace rr::server
