'use strict';
// The scripted behaviour of a CiA 402 drive on top of node-canopen's
// protocol stack: the power state machine (CiA 402 6.3.1, state coding and
// device control commands), profile position mode with the set-point
// handshake (CiA 402 12.2), quick stop per 0x605A, the reaction to a lost
// heartbeat of the master per 0x6007, and the device-profile-specific TPDO
// event (transmission type 255: on a change of the statusword, and on the
// event timer). The drive's axis is simulated in position counts.

const { NmtState } = require('canopen');

const S = {
    NOT_READY: 'not ready to switch on',
    DISABLED: 'switch on disabled',
    READY: 'ready to switch on',
    SWITCHED_ON: 'switched on',
    ENABLED: 'operation enabled',
    QUICK_STOP: 'quick stop active',
    FAULT_REACTION: 'fault reaction active',
    FAULT: 'fault',
};

// Statusword bits 0-6 per state (CiA 402 table "state coding"); bit 4
// (voltage enabled) set whenever the power stage is on.
const kStateBits = {
    [S.NOT_READY]: 0x0000, [S.DISABLED]: 0x0040, [S.READY]: 0x0031, [S.SWITCHED_ON]: 0x0033,
    [S.ENABLED]: 0x0037, [S.QUICK_STOP]: 0x0017, [S.FAULT_REACTION]: 0x001F, [S.FAULT]: 0x0008,
};
const kQuickStopBit = 0x0020;    // statusword bit 5: 1 = no quick stop
const kRemote = 0x0200;          // bit 9
const kTargetReached = 0x0400;   // bit 10
const kSetpointAck = 0x1000;     // bit 12
const kEmcyHeartbeat = 0x8130;   // life guard or heartbeat error (CiA 301 EMCY codes)

class Cia402Drive {
    constructor(device, options) {
        this.device = device;
        this.options = options;  // { rpm, countsPerRev, modeDelayMs }
        this.state = S.NOT_READY;
        this.position = 0;       // counts
        this.velocity = 0;       // counts/s
        this.target = 0;
        this.profile = null;     // { velocity, acceleration, deceleration } of the move, counts
        this.halted = false;
        this.stopping = null;    // quick stop ramp in progress: { deceleration, then }
        this.lastControlword = 0;
        this.ack = false;
        this.lastSent = {};      // per TPDO COB-ID: { time, statusword }
        this.eds = device.eds;
        this.state = S.DISABLED;  // transition 1: self test passed

        device.pdo.addListener('pdo', () => this.onControlword(this.value(0x6040)));
        this.eds.getEntry(0x6040).addListener('update', () => setImmediate(() => this.onControlword(this.value(0x6040))));
        this.eds.getEntry(0x6060).addListener('update', () => this.onModeWritten());
        device.nmt.addListener('timeout', (nodeId) => this.onHeartbeatLost(nodeId));
        this.publish();
    }

    value(index, sub) {
        return sub === undefined ? this.eds.getEntry(index).value : this.eds.getSubEntry(index, sub).value;
    }

    set(index, value) {
        this.eds.getEntry(index).value = value;
    }

    // Counts/s or counts/s^2 from a profile object (rpm and rpm/s in the rpm profile).
    rate(index) {
        const raw = this.value(index);
        return this.options.rpm ? raw * this.options.countsPerRev / 60 : raw;
    }

    onModeWritten() {
        // Drives switch modes asynchronously: 0x6061 follows after a while.
        const mode = this.value(0x6060);
        setTimeout(() => this.set(0x6061, mode), this.options.modeDelayMs);
    }

    onControlword(cw) {
        const previous = this.lastControlword;
        this.lastControlword = cw;
        const rising = (bit) => (cw & bit) !== 0 && (previous & bit) === 0;
        const command = (mask, value) => (cw & mask) === value;
        switch (this.state) {
            case S.FAULT:
                if (rising(0x80)) {  // transition 15: fault reset
                    this.state = S.DISABLED;
                    this.set(0x603F, 0);
                    this.device.emcy.write(0);
                }
                break;
            case S.DISABLED:
                if (command(0x87, 0x06)) this.state = S.READY;  // 2: shutdown
                break;
            case S.READY:
                if (command(0x82, 0x00) || command(0x86, 0x02)) this.state = S.DISABLED;  // 7
                else if (command(0x8F, 0x0F)) this.enable();  // 3 + 4
                else if (command(0x8F, 0x07)) this.state = S.SWITCHED_ON;  // 3
                break;
            case S.SWITCHED_ON:
                if (command(0x82, 0x00) || command(0x86, 0x02)) this.state = S.DISABLED;  // 10
                else if (command(0x87, 0x06)) this.state = S.READY;  // 6
                else if (command(0x8F, 0x0F)) this.enable();  // 4
                break;
            case S.ENABLED:
                if (command(0x82, 0x00)) this.powerOff(S.DISABLED);  // 9
                else if (command(0x86, 0x02)) this.quickStop();  // 11
                else if (command(0x87, 0x06)) this.powerOff(S.READY);  // 8
                else if (command(0x8F, 0x07)) this.powerOff(S.SWITCHED_ON);  // 5
                else this.operate(cw, previous);
                break;
            case S.QUICK_STOP:
                if (command(0x82, 0x00)) this.powerOff(S.DISABLED);  // 12
                else if (command(0x8F, 0x0F) && this.stopping === null) this.enable();  // 16
                break;
            default:
                break;
        }
        this.publish();
    }

    enable() {
        this.state = S.ENABLED;
        this.target = Math.round(this.position);  // hold where it is: enabling never jumps
        this.halted = false;
        this.profile = null;
    }

    powerOff(state) {
        // The power stage is off: the axis coasts to a stop at once in this
        // simulation (a brake would hold it).
        this.state = state;
        this.velocity = 0;
        this.stopping = null;
    }

    quickStop() {
        const option = this.value(0x605A);
        const deceleration = option === 1 || option === 5 ? this.rate(0x6084) : this.rate(0x6085);
        if (option === 0) {
            this.powerOff(S.DISABLED);
            return;
        }
        this.state = S.QUICK_STOP;
        this.stopping = { deceleration: Math.max(deceleration, 1), then: option <= 2 ? S.DISABLED : S.QUICK_STOP };
    }

    operate(cw, previous) {
        this.halted = (cw & 0x100) !== 0;
        const newSetpoint = (cw & 0x10) !== 0;
        if (newSetpoint && (previous & 0x10) === 0 && this.value(0x6061) === 1) {
            const relative = (cw & 0x40) !== 0;
            const target = this.value(0x607A);
            this.target = relative ? this.target + target : target;
            // A drive in rpm clamps the profile velocity to its max motor speed 0x6080.
            const maxVelocity = this.options.rpm ? this.value(0x6080) * this.options.countsPerRev / 60 : Infinity;
            this.profile = {
                velocity: Math.min(this.rate(0x6081), maxVelocity),
                acceleration: this.rate(0x6083), deceleration: this.rate(0x6084),
            };
            this.ack = true;
        } else if (!newSetpoint) {
            this.ack = false;
        }
    }

    onHeartbeatLost() {
        switch (this.value(0x6007)) {
            case 1:
                this.fault(kEmcyHeartbeat);
                return;
            case 2:
                this.device.emcy.write(kEmcyHeartbeat);
                if (this.state === S.ENABLED || this.state === S.QUICK_STOP) this.powerOff(S.DISABLED);
                break;
            case 3:
                this.device.emcy.write(kEmcyHeartbeat);
                if (this.state === S.ENABLED) this.quickStop();
                break;
            default:
                return;
        }
        this.publish();
    }

    fault(code) {
        this.set(0x603F, code);
        this.device.emcy.write(code);
        this.powerOff(S.FAULT);
        this.publish();
    }

    // Advances the axis by dt seconds.
    step(dt) {
        if (this.stopping !== null) {
            this.brake(this.stopping.deceleration, dt);
            if (this.velocity === 0) {
                if (this.stopping.then === S.DISABLED) this.state = S.DISABLED;
                this.stopping = null;
                this.target = Math.round(this.position);
            }
        } else if (this.state === S.ENABLED && this.profile !== null) {
            if (this.halted) this.brake(this.profile.deceleration, dt);
            else this.moveTowardsTarget(dt);
        }
        this.publish();
    }

    brake(deceleration, dt) {
        const dv = deceleration * dt;
        if (Math.abs(this.velocity) <= dv) {
            this.position += this.velocity * dt / 2;
            this.velocity = 0;
        } else {
            const v = this.velocity - Math.sign(this.velocity) * dv;
            this.position += (this.velocity + v) * dt / 2;
            this.velocity = v;
        }
    }

    // A trapezoid (or triangle) to the target with the move's profile.
    moveTowardsTarget(dt) {
        const { velocity: vmax, acceleration, deceleration } = this.profile;
        const distance = this.target - this.position;
        if (Math.abs(distance) < 0.5 && Math.abs(this.velocity) <= deceleration * dt) {
            this.position = this.target;
            this.velocity = 0;
            return;
        }
        const direction = Math.sign(distance);
        const towards = this.velocity * direction;  // > 0: moving towards the target
        const needed = towards > 0 ? towards * towards / (2 * Math.abs(distance)) : 0;
        let v;
        if (towards > 0 && needed >= deceleration) {
            v = this.velocity - direction * needed * dt;
        } else {
            v = this.velocity + direction * acceleration * dt;
            if (v * direction > vmax) v = direction * Math.max(vmax, Math.abs(this.velocity) - deceleration * dt);
        }
        let position = this.position + (this.velocity + v) * dt / 2;
        if ((this.target - position) * direction < 0) {  // would pass it: arrive
            position = this.target;
            v = 0;
        }
        this.position = position;
        this.velocity = v;
    }

    statusword() {
        let sw = kStateBits[this.state] | kRemote;
        if (this.state !== S.QUICK_STOP && this.state !== S.NOT_READY && this.state !== S.DISABLED &&
            this.state !== S.FAULT) sw |= kQuickStopBit;
        if (this.state === S.ENABLED) {
            const stopped = this.velocity === 0;
            if (stopped && (this.halted || Math.round(this.position) === this.target)) sw |= kTargetReached;
            if (this.ack) sw |= kSetpointAck;
        }
        return sw;
    }

    publish() {
        this.set(0x6064, Math.round(this.position) | 0);
        this.set(0x6041, this.statusword());
    }

    // Transmission type 255 is device-profile specific (CiA 301 7.5.2.35):
    // this drive sends such a TPDO when the statusword changes (no faster
    // than the inhibit time) and on the event timer. Called every tick.
    sendProfileTpdos(nowMs) {
        if (this.options.noType255 || this.device.nmt.state !== NmtState.OPERATIONAL)
            return;
        const statusword = this.value(0x6041);
        for (const pdo of Object.values(this.device.pdo.transmitMap)) {
            if (pdo.transmissionType !== 255) continue;
            const last = this.lastSent[pdo.cobId] || { time: -Infinity, statusword: -1 };
            const since = nowMs - last.time;
            const changed = statusword !== last.statusword && since >= pdo.inhibitTime / 10;
            const due = pdo.eventTime > 0 && since >= pdo.eventTime;
            if (changed || due) {
                this.device.pdo.write(pdo.cobId);
                this.lastSent[pdo.cobId] = { time: nowMs, statusword };
            }
        }
    }
}

module.exports = { Cia402Drive, DriveState: S };
