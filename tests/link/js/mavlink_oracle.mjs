// The independent side of skylane's MAVLink tests: node-mavlink (its serializer, packet
// splitter and parser, generated from the same XML definitions by other people).
//   node mavlink_oracle.mjs encode   prints one JSON line per message node-mavlink encoded:
//                                    {msgid, name, magic, payload_length, fields, hex}
//   node mavlink_oracle.mjs decode   reads hex frames (one per line) on stdin, prints for each
//                                    {msgid, seq, sysid, compid, fields} as node-mavlink parses it
import { MavLinkProtocolV2, MavLinkPacketSplitter, MavLinkPacketParser, minimal, common } from 'node-mavlink'
import { Readable } from 'node:stream'
import readline from 'node:readline'

const CLASSES = [minimal.Heartbeat, common.GlobalPositionInt, common.GpsRawInt, common.Gps2Raw, common.MissionRequest,
                 common.MissionCount, common.MissionAck, common.MissionRequestInt, common.MissionItemInt]
const REGISTRY = Object.fromEntries(CLASSES.map(c => [c.MSG_ID, c]))

// A value for field k of message m that fits its type and is exact in float32.
function valueFor(field, k, m) {
  const n = 3 + 7 * k + 11 * m
  switch (field.type) {
    case 'uint8_t': case 'uint8_t_mavlink_version': return n % 250
    case 'int8_t': return (n % 100) - 50
    case 'uint16_t': return (n * 257) % 65000
    case 'int16_t': return ((n * 257) % 60000) - 30000
    case 'uint32_t': return (n * 1000003) % 4000000000
    case 'int32_t': return ((n * 1000003) % 2000000000) - 1000000000
    case 'uint64_t': return BigInt(n) * 1000000007n
    case 'int64_t': return -BigInt(n) * 1000000007n
    case 'float': return n + 0.25
    case 'double': return n + 0.125
    default: throw new Error('type ' + field.type)
  }
}

const plain = v => typeof v === 'bigint' ? v.toString() : v

function encode() {
  const protocol = new MavLinkProtocolV2(42, 200)
  CLASSES.forEach((Clazz, m) => {
    const msg = new Clazz()
    const fields = {}
    Clazz.FIELDS.forEach((f, k) => { msg[f.name] = valueFor(f, k, m); fields[f.source] = plain(msg[f.name]) })
    const buffer = protocol.serialize(msg, m)
    console.log(JSON.stringify({ msgid: Clazz.MSG_ID, name: Clazz.MSG_NAME, magic: Clazz.MAGIC_NUMBER,
                                 payload_length: Clazz.PAYLOAD_LENGTH, fields, hex: buffer.toString('hex') }))
  })
}

async function decode() {
  const lines = []
  for await (const line of readline.createInterface({ input: process.stdin })) if (line.trim()) lines.push(line.trim())
  const bytes = Buffer.concat(lines.map(l => Buffer.from(l, 'hex')))
  const reader = Readable.from([bytes]).pipe(new MavLinkPacketSplitter()).pipe(new MavLinkPacketParser())
  for await (const packet of reader) {
    const Clazz = REGISTRY[packet.header.msgid]
    const fields = {}
    if (Clazz) {
      const data = packet.protocol.data(packet.payload, Clazz)
      Clazz.FIELDS.forEach(f => { fields[f.source] = plain(data[f.name]) })
    }
    console.log(JSON.stringify({ msgid: packet.header.msgid, seq: packet.header.seq, sysid: packet.header.sysid,
                                 compid: packet.header.compid, fields }))
  }
}

if (process.argv[2] === 'encode') encode()
else if (process.argv[2] === 'decode') await decode()
else { console.error('usage: mavlink_oracle.mjs encode|decode'); process.exit(2) }
