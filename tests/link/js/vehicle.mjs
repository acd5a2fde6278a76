// A small simulated vehicle for skylane's link tests, on node-mavlink (an implementation
// independent of skylane's). It flies an approved route from report.json in simulated time and
// sends its telemetry by UDP at 5 Hz of flight time: HEARTBEAT (1 Hz), GLOBAL_POSITION_INT and
// GPS_RAW_INT with h_acc/v_acc. It answers the mission protocol like an autopilot: a
// MISSION_COUNT is followed by one MISSION_REQUEST_INT per item and a MISSION_ACK; an accepted
// MISSION becomes its route at once (it steers back onto the new route's nearest point).
//
//   node vehicle.mjs --report REPORT.json --port PORT [--seconds S] [--pace-ms 3]
//        [--h-acc-mm 150] [--v-acc-mm 200] [--garbage]
//        [--gust-from T --gust-until T --gust-m 8]   pushed aside, then steered back
//        [--refuse]                                   refuses MISSION uploads (MAV_MISSION_DENIED)
//        [--silent-from T --silent-s 10]              sends nothing for a while (a lost link)
//        [--silent-on-upload S]                       the link is lost for S s from the first MISSION_COUNT heard
//        [--record FILE]                              also writes every byte it sends to FILE
// At the end it prints one JSON line: what it received and did.
import dgram from 'node:dgram'
import fs from 'node:fs'
import { PassThrough } from 'node:stream'
import { MavLinkProtocolV2, MavLinkPacketSplitter, MavLinkPacketParser, minimal, common } from 'node-mavlink'

const args = Object.fromEntries(process.argv.slice(2).reduce((acc, a, i, all) => {
  if (a.startsWith('--')) acc.push([a.slice(2), all[i + 1] && !all[i + 1].startsWith('--') ? all[i + 1] : true])
  return acc
}, []))
const num = (k, d) => (args[k] === undefined ? d : Number(args[k]))
const report = JSON.parse(fs.readFileSync(args.report, 'utf8'))
const port = num('port')
const hAcc = num('h-acc-mm', 150), vAcc = num('v-acc-mm', 200)
const duration = num('seconds', report.route[report.route.length - 1].eta_s)
const pace = num('pace-ms', 3)
const gust = { from: num('gust-from', -1), until: num('gust-until', -1), m: num('gust-m', 8) }
const silent = { from: num('silent-from', -1), s: num('silent-s', 0) }
const departureMs = Date.parse(report.departure)
const protocol = new MavLinkProtocolV2(1, 1)  // system 1, autopilot component
const socket = dgram.createSocket('udp4')
const summary = { missions: 0, fences: 0, acked: 0, refused: 0, route_changes: 0, items: [], gps_sent: 0 }
let seq = 0

// --- a local plane around the route's start (equirectangular: ample for a few km) -----------
const R = 6378137, lat0 = report.route[0].lat * Math.PI / 180, lon0 = report.route[0].lon * Math.PI / 180
const undulation = report.route[0].h_ell_m - report.route[0].alt_amsl_m
const toXY = (lat, lon) => [(lon * Math.PI / 180 - lon0) * Math.cos(lat0) * R, (lat * Math.PI / 180 - lat0) * R]
const toLatLon = (x, y) => [(y / R + lat0) * 180 / Math.PI, (x / (R * Math.cos(lat0)) + lon0) * 180 / Math.PI]

let route = report.route.map(p => ({ x: toXY(p.lat, p.lon)[0], y: toXY(p.lat, p.lon)[1], h: p.h_ell_m }))
const speed = (() => {  // the approved route's ground speed
  const a = report.route[0], b = report.route[report.route.length - 1]
  let len = 0
  for (let i = 1; i < route.length; i++) len += Math.hypot(route[i].x - route[i - 1].x, route[i].y - route[i - 1].y)
  return len / Math.max(1, b.eta_s - a.eta_s)
})()

// Nearest point of the route polyline: its distance along the route and the point.
function project(x, y) {
  let best = { d: Infinity, s: 0, x: route[0].x, y: route[0].y, h: route[0].h, i: 1 }, s = 0
  for (let i = 1; i < route.length; i++) {
    const a = route[i - 1], b = route[i], L = Math.hypot(b.x - a.x, b.y - a.y) || 1e-9
    const f = Math.min(1, Math.max(0, ((x - a.x) * (b.x - a.x) + (y - a.y) * (b.y - a.y)) / (L * L)))
    const px = a.x + f * (b.x - a.x), py = a.y + f * (b.y - a.y), d = Math.hypot(x - px, y - py)
    if (d < best.d) best = { d, s: s + f * L, x: px, y: py, h: a.h + f * (b.h - a.h), i }
    s += L
  }
  return best
}
// The point `s` metres along the route, and the unit vector along it there.
function pointAt(s) {
  for (let i = 1; i < route.length; i++) {
    const a = route[i - 1], b = route[i], L = Math.hypot(b.x - a.x, b.y - a.y) || 1e-9
    if (s <= L || i === route.length - 1) {
      const f = Math.min(1, Math.max(0, s / L))
      return { x: a.x + f * (b.x - a.x), y: a.y + f * (b.y - a.y), h: a.h + f * (b.h - a.h), ux: (b.x - a.x) / L, uy: (b.y - a.y) / L }
    }
    s -= L
  }
}

// --- the flight: along the route at its speed; off it, steered back at 0.5 /s ---------------
let pos = { x: route[0].x, y: route[0].y, h: route[0].h }
function step(t, dt) {
  const p = project(pos.x, pos.y)
  const ahead = pointAt(p.s + speed * dt)
  const ex = pos.x - p.x, ey = pos.y - p.y
  const keep = Math.max(0, 1 - 0.5 * dt)                   // cross-track error decays
  pos = { x: ahead.x + ex * keep, y: ahead.y + ey * keep, h: ahead.h }
  if (t >= gust.from && t < gust.until) {                   // the gust holds it gust.m to the left
    const q = project(pos.x, pos.y), at = pointAt(q.s)
    pos = { x: q.x - at.uy * gust.m, y: q.y + at.ux * gust.m, h: pos.h }
  }
}

// --- the mission protocol, as an autopilot answers it ----------------------------------------
let upload = null  // { type, count, items, from: {sysid, compid} }
function request(k) {
  const r = new common.MissionRequestInt()
  r.targetSystem = upload.from.sysid; r.targetComponent = upload.from.compid; r.seq = k; r.missionType = upload.type
  return send(protocol.serialize(r, seq++ % 256))
}
function ack(type) {
  const a = new common.MissionAck()
  a.targetSystem = upload.from.sysid; a.targetComponent = upload.from.compid; a.type = type; a.missionType = upload.type
  return send(protocol.serialize(a, seq++ % 256))
}
function takeMission(items) {  // an accepted MISSION becomes the route from here on
  const pts = items.filter(it => it.command === 16 || it.command === 21 || it.command === 22)
                   .map(it => { const [x, y] = toXY(it.x / 1e7, it.y / 1e7); return { x, y, h: it.z + undulation } })
  const land = pts.length > 1 && items[items.length - 1].command === 21 ? pts.pop() : null
  if (land) pts.push({ x: land.x, y: land.y, h: pts[pts.length - 1].h })  // fly to the goal at height, then land
  route = pts
  summary.route_changes++
}
async function onPacket(packet) {
  if (quiet) return  // a lost link loses both ways
  const id = packet.header.msgid
  if (args['silent-on-upload'] && !silentOnce && id === common.MissionCount.MSG_ID) {
    silentOnce = true  // the link drops just as the upload begins: this message is lost too
    silent.from = simTime; silent.s = num('silent-on-upload', 10); quiet = true
    return
  }
  if (id === common.MissionCount.MSG_ID) {
    const c = packet.protocol.data(packet.payload, common.MissionCount)
    upload = { type: c.missionType, count: c.count, items: [], from: { sysid: packet.header.sysid, compid: packet.header.compid } }
    if (c.missionType === 0) summary.missions++; else summary.fences++
    await request(0)
  } else if (id === common.MissionItemInt.MSG_ID && upload) {
    const it = packet.protocol.data(packet.payload, common.MissionItemInt)
    if (it.seq !== upload.items.length) return
    upload.items.push({ command: it.command, x: it.x, y: it.y, z: it.z, param1: it.param1 })
    if (upload.items.length < upload.count) return request(upload.items.length)
    const refuse = args.refuse && upload.type === 0
    await ack(refuse ? 14 : 0)  // MAV_MISSION_DENIED : MAV_MISSION_ACCEPTED
    if (refuse) summary.refused++; else summary.acked++
    if (!refuse && upload.type === 0) { takeMission(upload.items); summary.items.push(upload.items.length) }
    upload = null
  }
}
const input = new PassThrough()
input.pipe(new MavLinkPacketSplitter()).pipe(new MavLinkPacketParser()).on('data', p => { onPacket(p) })
socket.on('message', msg => input.write(msg))

// --- telemetry --------------------------------------------------------------------------------
let quiet = false
let silentOnce = false
let simTime = 0
const record = args.record ? fs.openSync(args.record, 'w') : null
const send = buffer => {
  if (quiet) return Promise.resolve()
  if (record !== null) fs.writeSync(record, buffer)
  return new Promise(resolve => socket.send(buffer, port, '127.0.0.1', () => resolve()))
}
const frame = msg => protocol.serialize(msg, seq++ % 256)
const sleep = ms => new Promise(resolve => setTimeout(resolve, ms))

async function telemetry(k, t) {
  const [lat, lon] = toLatLon(pos.x, pos.y)
  if (k % 5 === 0) {
    const hb = new minimal.Heartbeat()
    hb.type = 2; hb.autopilot = 12; hb.baseMode = 217; hb.systemStatus = 4; hb.mavlinkVersion = 3
    await send(frame(hb))
  }
  const gpi = new common.GlobalPositionInt()
  gpi.timeBootMs = Math.round(t * 1000); gpi.lat = Math.round(lat * 1e7); gpi.lon = Math.round(lon * 1e7)
  gpi.alt = Math.round((pos.h - undulation) * 1000); gpi.relativeAlt = 60000
  await send(frame(gpi))
  const raw = new common.GpsRawInt()
  raw.timeUsec = BigInt(departureMs + Math.round(t * 1000)) * 1000n
  raw.fixType = 3; raw.lat = Math.round(lat * 1e7); raw.lon = Math.round(lon * 1e7)
  raw.alt = Math.round((pos.h - undulation) * 1000); raw.altEllipsoid = Math.round(pos.h * 1000)
  raw.eph = 80; raw.epv = 120; raw.vel = Math.round(speed * 100); raw.cog = 0; raw.satellitesVisible = 12
  raw.hAcc = hAcc; raw.vAcc = vAcc; raw.velAcc = 100; raw.hdgAcc = 0; raw.yaw = 0
  let bytes = frame(raw)
  if (args.garbage && k === 10) await send(Buffer.from([0x00, 0x55, 0xfd, 0x02, 0x99]))  // junk
  if (args.garbage && k === 20) { bytes = Buffer.from(bytes); bytes[15] ^= 0x01 }           // a flipped bit
  if (args.garbage && k === 30) await send(bytes.subarray(0, 8))                              // a truncated copy
  if (!quiet && !(args.garbage && k === 20)) summary.gps_sent++
  await send(bytes)
}

await new Promise(resolve => socket.bind(0, '127.0.0.1', resolve))
for (let k = 0; k * 0.2 <= duration + 1e-9; k++) {
  const t = k * 0.2
  simTime = t
  if (k > 0) step(t, 0.2)
  quiet = t >= silent.from && t < silent.from + silent.s
  await telemetry(k, t)
  await sleep(pace)  // paced: the receiver's socket buffer never overflows, and uploads fit in
}
await sleep(200)
console.log(JSON.stringify(summary))
socket.close()
