// Server-Sent Events over fetch(): the page must send `Authorization: Bearer …`, which the
// browser's EventSource cannot. The parser follows the WHATWG HTML Living Standard, §9.2
// "Server-sent events", "Parsing an event stream" and "Interpreting an event stream": lines end
// in CRLF, LF or CR; a blank line dispatches; `data` lines join with LF; a line starting with
// ':' is a comment; `id` sets the last event id (kept even for events without data); `retry`
// sets the reconnection time in ms.

/** Incremental text/event-stream parser: feed() decoded text, get dispatched events back. */
export class EventStreamParser {
  constructor() {
    this.buffer_ = '';
    this.data_ = [];
    this.type_ = '';
    this.lastEventId = '';
    this.retryMs = null;
  }

  /** Parses `text` (a chunk, possibly ending mid-line); returns the events completed by it. */
  feed(text) {
    this.buffer_ += text;
    const events = [];
    for (;;) {
      const m = /\r\n|\n|\r/.exec(this.buffer_);
      if (!m) break;
      // A CR at the very end may be the first half of a CRLF still in flight.
      if (m[0] === '\r' && m.index === this.buffer_.length - 1) break;
      const line = this.buffer_.slice(0, m.index);
      this.buffer_ = this.buffer_.slice(m.index + m[0].length);
      const e = this.line_(line);
      if (e) events.push(e);
    }
    return events;
  }

  line_(line) {
    if (line === '') return this.dispatch_();
    if (line.startsWith(':')) return null;
    const colon = line.indexOf(':');
    const field = colon < 0 ? line : line.slice(0, colon);
    let value = colon < 0 ? '' : line.slice(colon + 1);
    if (value.startsWith(' ')) value = value.slice(1);
    if (field === 'data') this.data_.push(value);
    else if (field === 'event') this.type_ = value;
    else if (field === 'id' && !value.includes('\0')) this.lastEventId = value;
    else if (field === 'retry' && /^\d+$/.test(value)) this.retryMs = Number(value);
    return null;
  }

  dispatch_() {
    const data = this.data_;
    const type = this.type_ || 'message';
    this.data_ = [];
    this.type_ = '';
    if (data.length === 0) return null;
    return { type, data: data.join('\n'), id: this.lastEventId };
  }
}

/**
 * Opens `url` as an event stream with `headers`, calls onEvent({type, data, id}) per event and
 * reconnects after a drop, sending Last-Event-ID so that the server resumes after the last event
 * seen. onState(state, detail) reports 'open', 'closed' (will retry) and 'failed' (HTTP 4xx: not
 * retried). Returns {close()}.
 */
export function openEventStream(url, headers, onEvent, onState = () => {}) {
  const parser = new EventStreamParser();
  let controller = null;
  let stopped = false;
  let delayMs = 1000;
  const kMaxDelayMs = 30000;  // back off to at most 30 s between reconnections

  async function connect() {
    controller = new AbortController();
    const h = { ...headers, Accept: 'text/event-stream' };
    if (parser.lastEventId) h['Last-Event-ID'] = parser.lastEventId;
    const response = await fetch(url, { headers: h, signal: controller.signal, cache: 'no-store' });
    if (response.status >= 400 && response.status < 500) {
      onState('failed', `${url}: HTTP ${response.status}`);
      stopped = true;
      return;
    }
    if (!response.ok || !response.body) throw new Error(`${url}: HTTP ${response.status}`);
    onState('open', parser.lastEventId);
    delayMs = parser.retryMs ?? 1000;
    const reader = response.body.pipeThrough(new TextDecoderStream()).getReader();
    for (;;) {
      const { value, done } = await reader.read();
      if (done) break;
      for (const e of parser.feed(value)) onEvent(e);
    }
  }

  async function loop() {
    while (!stopped) {
      try {
        await connect();
        if (!stopped) onState('closed', 'stream ended');
      } catch (err) {
        if (stopped) break;
        onState('closed', String(err.message || err));
      }
      if (stopped) break;
      await new Promise((resolve) => setTimeout(resolve, delayMs));
      delayMs = Math.min(kMaxDelayMs, delayMs * 2);
    }
  }

  loop();
  return {
    close() {
      stopped = true;
      if (controller) controller.abort();
    },
    get lastEventId() { return parser.lastEventId; },
  };
}
