'use strict';
// The bus between node-canopen devices and the daemon's `unix:` CAN
// transport (drivers/can/fd_can_transport.h): a Unix stream socket carrying
// 16-byte Linux `struct can_frame` records (can_id uint32 in host order,
// len, 3 bytes padding, 8 data bytes). Every frame from a client goes to
// every device and to the other clients; every frame from a device goes to
// the clients and to the other devices, as on a real bus. A client may
// come and go (the daemon killed and restarted); the devices keep running.

const fs = require('fs');
const net = require('net');
const os = require('os');

const kRecordBytes = 16;
const kFlagBits = 0xE0000000; // EFF, RTR, ERR: only classic data frames are used

if (os.endianness() !== 'LE')
    throw new Error('the record layout below assumes a little-endian host');

function encode({ id, data }) {
    const record = Buffer.alloc(kRecordBytes);
    record.writeUInt32LE(id & 0x7FF, 0);
    record.writeUInt8(data.length, 4);
    data.copy(record, 8, 0, Math.min(8, data.length));
    return record;
}

// null for a record with a flag bit or a length over 8 (dropped, counted).
function decode(record) {
    const canId = record.readUInt32LE(0);
    const len = record.readUInt8(4);
    if ((canId & kFlagBits) !== 0 || canId > 0x7FF || len > 8)
        return null;
    return { id: canId, data: Buffer.from(record.subarray(8, 8 + len)) };
}

class FrameLog {
    constructor(path) {
        this.fd = path ? fs.openSync(path, 'w') : null;
        this.start = process.hrtime.bigint();
    }

    write(direction, { id, data }) {
        if (this.fd === null)
            return;
        const ms = Number(process.hrtime.bigint() - this.start) / 1e6;
        const bytes = [...data].map((b) => b.toString(16).padStart(2, '0')).join(' ');
        fs.writeSync(this.fd, `${ms.toFixed(1).padStart(9)} ${direction} ${id.toString(16).padStart(3, '0')} [${data.length}] ${bytes}\n`);
    }
}

class Bridge {
    constructor({ socketPath, frameLogPath }) {
        this.socketPath = socketPath;
        this.devices = [];
        this.clients = new Set();
        this.log = new FrameLog(frameLogPath);
        this.malformed = 0;
    }

    addDevice(device) {
        this.devices.push(device);
        device.addListener('message', (message) => this._fromDevice(device, message));
    }

    listen(onReady) {
        try { fs.unlinkSync(this.socketPath); } catch (e) { /* not there */ }
        this.server = net.createServer((socket) => this._accept(socket));
        this.server.listen(this.socketPath, onReady);
    }

    close() {
        for (const socket of this.clients)
            socket.destroy();
        if (this.server)
            this.server.close();
    }

    _accept(socket) {
        this.clients.add(socket);
        let pending = Buffer.alloc(0);
        socket.on('data', (chunk) => {
            pending = Buffer.concat([pending, chunk]);
            while (pending.length >= kRecordBytes) {
                const frame = decode(pending.subarray(0, kRecordBytes));
                pending = pending.subarray(kRecordBytes);
                if (frame === null) {
                    ++this.malformed;
                    continue;
                }
                this._fromClient(socket, frame);
            }
        });
        const forget = () => this.clients.delete(socket);
        socket.on('close', forget);
        socket.on('error', forget);
    }

    _fromClient(source, frame) {
        this.log.write('>', frame);
        const record = encode(frame);
        for (const client of this.clients) {
            if (client !== source)
                client.write(record);
        }
        for (const device of this.devices)
            device.receive(frame);
    }

    _fromDevice(source, frame) {
        this.log.write('<', frame);
        const record = encode(frame);
        for (const client of this.clients)
            client.write(record);
        // Later, not from inside the sender's own handler.
        setImmediate(() => {
            for (const device of this.devices) {
                if (device !== source)
                    device.receive(frame);
            }
        });
    }
}

module.exports = { Bridge, encode, decode };
