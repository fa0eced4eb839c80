// The demo robot's sensor packets (wire `packets` of the gateway's demo device `create`), live, with the
// connection state: stop the gateway and start it again, and the page carries on by itself.
import { StrictMode } from "react";
import { createRoot } from "react-dom/client";
import { useServiceSubscription, useWire } from "./use_subscription.js";

// The demo robot sends its packets to the clients that asked for them: ask again on every connection.
const startStreaming = (client, create) => create.StartStreaming().catch((e) => console.error(e));

function PacketView({ url }) {
  const sub = useServiceSubscription(url, { onConnect: startStreaming });
  const { value, time, count, connected, connects } = useWire(sub, "packets");
  return (
    <section>
      <p>
        Connection: <span id="state">{connected ? "connected" : "reconnecting"}</span>, made{" "}
        <span id="connects">{connects}</span> times
      </p>
      <p>
        Sensor packet: <span id="packet">{value ? `ID ${value.ID}, ${value.Data.length} bytes` : "none yet"}</span>
        {time ? ` at ${new Date(time.seconds * 1000).toISOString()}` : ""}
      </p>
      <p>
        Values received: <span id="count">{count}</span>
      </p>
    </section>
  );
}

// The gateway that serves this page serves the device too: the URL is relative to the page's folder.
const folder = new URL(".", location.href);
const url = `${folder.protocol === "https:" ? "rr+wss" : "rr+ws"}://${folder.host}${folder.pathname}?service=create`;
createRoot(document.getElementById("root")).render(
  <StrictMode>
    <h1>Create robot (React)</h1>
    <PacketView url={url} />
  </StrictMode>,
);
