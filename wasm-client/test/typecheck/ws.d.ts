// The parts of node and the `ws` package that usage.ts uses (no @types packages needed).
declare module "ws" {
  const WebSocket: unknown;
  export default WebSocket;
}
declare const process: { argv: string[]; exit(code: number): never };
