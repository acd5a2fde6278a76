// The service's HTTP API (docs/service_api.md): every /v1 route takes the bearer token.

/** The token: `#token=…` in the address (taken and removed from it), else the session's. */
export function takeToken(location, history, storage) {
  const hash = new URLSearchParams(location.hash.replace(/^#/, ''));
  const fromHash = hash.get('token');
  if (fromHash) {
    storage.setItem('skylane.token', fromHash);
    hash.delete('token');
    const rest = hash.toString();
    history.replaceState(null, '', location.pathname + location.search + (rest ? `#${rest}` : ''));
    return fromHash;
  }
  return storage.getItem('skylane.token');
}

/** An HTTP error answered by the service: status and its one-line {"error": …} message. */
export class ApiError extends Error {
  constructor(path, status, message) {
    super(`${path}: HTTP ${status}${message ? `: ${message}` : ''}`);
    this.status = status;
  }
}

export class Api {
  constructor(token, base = '') {
    this.token = token;
    this.base = base;
  }

  headers() { return { Authorization: `Bearer ${this.token}` }; }

  async get(path) {
    const response = await fetch(this.base + path, { headers: this.headers(), cache: 'no-store' });
    if (!response.ok) {
      let message = '';
      try {
        message = (await response.json()).error || '';
      } catch (_) { /* a body that is not JSON: the status says enough */ }
      throw new ApiError(path, response.status, message);
    }
    return response.json();
  }

  zonesets() { return this.get('/v1/zonesets'); }
  zonesetGeojson(id) { return this.get(`/v1/zonesets/${encodeURIComponent(id)}/geojson`); }
  approvals() { return this.get('/v1/approvals'); }
  approvalRoute(id) { return this.get(`/v1/approvals/${encodeURIComponent(id)}/route.geojson`); }
  flights() { return this.get('/v1/flights'); }
  flightRoute(id) { return this.get(`/v1/flights/${encodeURIComponent(id)}/route`); }
  eventsUrl() { return `${this.base}/v1/events`; }
}
