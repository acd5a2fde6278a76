// A small simulated vehicle for skylane's link tests, on node-mavlink (an implementation
// independent of skylane's). It flies an approved route from report.json, fast-forwarded in
// simulated time, and sends its telemetry by UDP at 5 Hz of flight time: HEARTBEAT (1 Hz),
// GLOBAL_POSITION_INT and GPS_RAW_INT with h_acc/v_acc.
//   node vehicle.mjs --report REPORT.json --port PORT [--h-acc-mm 150] [--v-acc-mm 200]
//                    [--seconds S] [--pace-ms 3] [--garbage]
// --garbage interleaves junk bytes, a frame with a flipped bit and a truncated frame.
import dgram from 'node:dgram'
import fs from 'node:fs'
import { MavLinkProtocolV2, minimal, common } from 'node-mavlink'

const args = Object.fromEntries(process.argv.slice(2).reduce((acc, a, i, all) => {
  if (a.startsWith('--')) acc.push([a.slice(2), all[i + 1] && !all[i + 1].startsWith('--') ? all[i + 1] : true])
  return acc
}, []))
const report = JSON.parse(fs.readFileSync(args.report, 'utf8'))
const route = report.route
const port = Number(args.port)
const hAcc = Number(args['h-acc-mm'] ?? 150), vAcc = Number(args['v-acc-mm'] ?? 200)
const duration = Number(args.seconds ?? route[route.length - 1].eta_s)
const pace = Number(args['pace-ms'] ?? 3)
const departureMs = Date.parse(report.departure)
const protocol = new MavLinkProtocolV2(1, 1)  // system 1, autopilot component
const socket = dgram.createSocket('udp4')
let seq = 0

// The route point t seconds after departure (linear between points by ETA, held at the ends).
function along(t) {
  let i = 1
  while (i < route.length - 1 && t > route[i].eta_s) i++
  const a = route[i - 1], b = route[i]
  const f = Math.min(1, Math.max(0, (t - a.eta_s) / Math.max(1e-9, b.eta_s - a.eta_s)))
  const mix = k => a[k] + f * (b[k] - a[k])
  return { lat: mix('lat'), lon: mix('lon'), h: mix('h_ell_m'), amsl: mix('alt_amsl_m') }
}

const send = buffer => new Promise(resolve => socket.send(buffer, port, '127.0.0.1', () => resolve()))
const frame = msg => protocol.serialize(msg, seq++ % 256)
const sleep = ms => new Promise(resolve => setTimeout(resolve, ms))

async function fly() {
  for (let k = 0; k * 0.2 <= duration + 1e-9; k++) {
    const t = k * 0.2
    const p = along(t)
    if (k % 5 === 0) {
      const hb = new minimal.Heartbeat()
      hb.type = 2; hb.autopilot = 12; hb.baseMode = 217; hb.systemStatus = 4; hb.mavlinkVersion = 3
      await send(frame(hb))
    }
    const gpi = new common.GlobalPositionInt()
    gpi.timeBootMs = Math.round(t * 1000); gpi.lat = Math.round(p.lat * 1e7); gpi.lon = Math.round(p.lon * 1e7)
    gpi.alt = Math.round(p.amsl * 1000); gpi.relativeAlt = 60000
    await send(frame(gpi))
    const raw = new common.GpsRawInt()
    raw.timeUsec = BigInt(departureMs + Math.round(t * 1000)) * 1000n
    raw.fixType = 3; raw.lat = Math.round(p.lat * 1e7); raw.lon = Math.round(p.lon * 1e7)
    raw.alt = Math.round(p.amsl * 1000); raw.altEllipsoid = Math.round(p.h * 1000)
    raw.eph = 80; raw.epv = 120; raw.vel = 1000; raw.cog = 0; raw.satellitesVisible = 12
    raw.hAcc = hAcc; raw.vAcc = vAcc; raw.velAcc = 100; raw.hdgAcc = 0; raw.yaw = 0
    let bytes = frame(raw)
    if (args.garbage && k === 10) await send(Buffer.from([0x00, 0x55, 0xfd, 0x02, 0x99]))  // junk
    if (args.garbage && k === 20) { bytes = Buffer.from(bytes); bytes[15] ^= 0x01 }           // a flipped bit
    if (args.garbage && k === 30) await send(bytes.subarray(0, 8))                              // a truncated copy
    await send(bytes)
    await sleep(pace)  // paced, so that a slower receiver's socket buffer never overflows
  }
}

await fly()
socket.close()
