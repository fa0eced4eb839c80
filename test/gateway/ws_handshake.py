"""The client side of a WebSocket opening handshake (RFC 6455 §4.1) on a plain socket, for the tests that
write and read frames themselves (ws_conformance_test.py, ws_deflate_test.py)."""
import base64
import os


def open_handshake(sock, port, path="/", subprotocol=None, extensions=None):
    """Sends the upgrade request and reads the answer's head. Returns (headers, rest): the response
    headers with lower-case names, and the bytes read past the head (the first frames, if any). Raises
    AssertionError when the connection closes during the handshake or the status is not 101."""
    lines = ["GET %s HTTP/1.1" % path, "Host: 127.0.0.1:%d" % port, "Upgrade: websocket", "Connection: Upgrade",
             "Sec-WebSocket-Key: " + base64.b64encode(os.urandom(16)).decode(), "Sec-WebSocket-Version: 13"]
    if subprotocol:
        lines.append("Sec-WebSocket-Protocol: " + subprotocol)
    if extensions:
        lines.append("Sec-WebSocket-Extensions: " + extensions)
    sock.sendall(("\r\n".join(lines) + "\r\n\r\n").encode())
    head = b""
    while b"\r\n\r\n" not in head:
        chunk = sock.recv(4096)
        if not chunk:
            raise AssertionError("connection closed during the handshake: %r" % head)
        head += chunk
    head, rest = head.split(b"\r\n\r\n", 1)
    status = head.split(b"\r\n")[0]
    if b" 101 " not in status + b" ":
        raise AssertionError("handshake refused: %r" % head[:200])
    headers = {}
    for line in head.split(b"\r\n")[1:]:
        k, _, v = line.decode("latin-1").partition(":")
        headers[k.strip().lower()] = v.strip()
    return headers, rest
