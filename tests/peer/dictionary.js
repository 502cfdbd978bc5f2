'use strict';
// Object dictionaries of the peer's nodes, built with node-canopen's Eds
// from CiA 301 (communication objects), CiA 402 (drive) and CiA 406
// (encoder), with the vendor quirks as options. Nothing here is taken from
// the daemon or the virtual robot: the defaults are the profiles' own
// (heartbeat producer off, CiA 402 predefined PDOs), so nothing works
// unless the master configures it.

const { AccessType, DataType, Eds, ObjectType } = require('canopen');

const { READ_ONLY: RO, READ_WRITE: RW } = AccessType;

function variable(eds, index, name, dataType, accessType, defaultValue, limits = {}) {
    return eds.addEntry(index, {
        parameterName: name, objectType: ObjectType.VAR, dataType, accessType,
        defaultValue, pdoMapping: true, ...limits,
    });
}

function record(eds, index, name, subs) {
    const entry = eds.addEntry(index, { parameterName: name, objectType: ObjectType.RECORD });
    subs.forEach(([sub, subName, dataType, accessType, defaultValue, limits], i) => {
        entry.addSubObject(sub === undefined ? i + 1 : sub, {
            parameterName: subName, objectType: ObjectType.VAR, dataType, accessType, defaultValue, ...(limits || {}),
        });
    });
    return entry;
}

// One PDO's communication and mapping records (CiA 301 7.5.2.35-38).
// options.rtrFixed: COB-ID bit 30 reads 1 whatever is written (a device
// without RTR, as the Lika manual requires); options.maxType: the highest
// TPDO transmission type it takes (254 for a device without 255: a write of
// 255 is refused with abort 0x06090031).
function pdo(eds, transmit, number, cobId, mapped, options) {
    const comm = (transmit ? 0x1800 : 0x1400) + number - 1;
    const kind = transmit ? 'TPDO' : 'RPDO';
    const rtrBit = options.rtrFixed ? 0x40000000 : 0;
    const valid = mapped.length > 0 ? 0 : 0x80000000;
    const subs = [
        [1, 'COB-ID', DataType.UNSIGNED32, RW, (valid | rtrBit | cobId) >>> 0],
        [2, 'transmission type', DataType.UNSIGNED8, RW, 254, transmit ? { highLimit: options.maxType } : {}],
    ];
    if (transmit) {
        subs.push([3, 'inhibit time', DataType.UNSIGNED16, RW, 0]);
        subs.push([5, 'event timer', DataType.UNSIGNED16, RW, 0]);
    }
    const commEntry = record(eds, comm, `${kind}${number} communication parameter`, subs);
    const mapEntry = record(eds, comm + 0x200, `${kind}${number} mapping parameter`,
        Array.from({ length: 8 }, (_, i) => [i + 1, `mapped object ${i + 1}`, DataType.UNSIGNED32, RW, mapped[i] || 0]));
    mapEntry[0].value = mapped.length;
    if (options.rtrFixed) {
        // Sub-objects report their updates through their record.
        const cob = commEntry[1];
        commEntry.addListener('update', (obj) => {
            if (obj === cob && (cob.value & 0x40000000) === 0)
                cob.value = (cob.value | 0x40000000) >>> 0;
        });
    }
}

function communication(eds, id, { deviceType, vendorId, productCode, heartbeatConsumer }) {
    eds.getEntry(0x1000).value = deviceType;
    eds.setIdentity({ vendorId, productCode, revisionNumber: 1, serialNumber: id });
    eds.addSdoServerParameter(0, 0x580 + id, 0x600 + id);
    eds.setEmcyCobId(0x80 + id);
    variable(eds, 0x1017, 'Producer heartbeat time', DataType.UNSIGNED16, RW, 0);
    if (heartbeatConsumer) {
        const consumer = eds.addEntry(0x1016, { parameterName: 'Consumer heartbeat time', objectType: ObjectType.ARRAY });
        consumer.addSubObject(1, { parameterName: 'Consumer heartbeat time 1', objectType: ObjectType.VAR,
            dataType: DataType.UNSIGNED32, accessType: RW, defaultValue: 0 });
    }
}

const map = (index, sub, bits) => ((index << 16) | (sub << 8) | bits) >>> 0;

// A CiA 402 drive in profile position mode. quirks: rtrFixed, noType255,
// rpm (velocity objects in motor rpm and rpm/s, 0x60A9 saying so).
function driveDictionary(id, quirks) {
    const eds = new Eds();
    communication(eds, id, { deviceType: 0x00020192, vendorId: 0x0000CAFE, productCode: 0x402, heartbeatConsumer: true });
    const options = { rtrFixed: quirks.rtrFixed, maxType: quirks.noType255 ? 254 : 255 };
    for (let n = 1; n <= 4; ++n) {
        // CiA 402 predefined connection set: RPDO1 = controlword, TPDO1 = statusword.
        pdo(eds, false, n, 0x100 + 0x100 * n + id, n === 1 ? [map(0x6040, 0, 16)] : [], options);
        pdo(eds, true, n, 0x80 + 0x100 * n + id, n === 1 ? [map(0x6041, 0, 16)] : [], options);
    }
    variable(eds, 0x603F, 'Error code', DataType.UNSIGNED16, RO, 0);
    variable(eds, 0x6040, 'Controlword', DataType.UNSIGNED16, RW, 0);
    variable(eds, 0x6041, 'Statusword', DataType.UNSIGNED16, RO, 0);
    variable(eds, 0x6007, 'Abort connection option code', DataType.INTEGER16, RW, 1, { lowLimit: 0, highLimit: 3 });
    variable(eds, 0x605A, 'Quick stop option code', DataType.INTEGER16, RW, 2, { lowLimit: 0, highLimit: 8 });
    variable(eds, 0x6060, 'Modes of operation', DataType.INTEGER8, RW, 0);
    variable(eds, 0x6061, 'Modes of operation display', DataType.INTEGER8, RO, 0);
    variable(eds, 0x6064, 'Position actual value', DataType.INTEGER32, RO, 0);
    variable(eds, 0x6065, 'Following error window', DataType.UNSIGNED32, RW, 0xFFFFFFFF);
    variable(eds, 0x607A, 'Target position', DataType.INTEGER32, RW, 0);
    record(eds, 0x607D, 'Software position limit', [
        [1, 'Min position limit', DataType.INTEGER32, RW, -0x80000000],
        [2, 'Max position limit', DataType.INTEGER32, RW, 0x7FFFFFFF],
    ]);
    variable(eds, 0x6081, 'Profile velocity', DataType.UNSIGNED32, RW, 0);
    variable(eds, 0x6083, 'Profile acceleration', DataType.UNSIGNED32, RW, 0);
    variable(eds, 0x6084, 'Profile deceleration', DataType.UNSIGNED32, RW, 0);
    variable(eds, 0x6085, 'Quick stop deceleration', DataType.UNSIGNED32, RW, 0);
    if (quirks.rpm) {
        // maxon EPOS4 style: velocities in rpm, accelerations in rpm/s.
        variable(eds, 0x6080, 'Max motor speed', DataType.UNSIGNED32, RW, quirks.maxMotorRpm);
        record(eds, 0x608F, 'Position encoder resolution', [
            [1, 'Encoder increments', DataType.UNSIGNED32, RW, quirks.countsPerRev],
            [2, 'Motor revolutions', DataType.UNSIGNED32, RW, 1],
        ]);
        variable(eds, 0x60A9, 'SI unit velocity', DataType.UNSIGNED32, RW, 0x00B44700);
    }
    return eds;
}

// A CiA 406 encoder. quirks.encoderTpdos: how many TPDOs it has (2 for
// Kübler Sendix / SIKO style devices, 4 otherwise); quirks.noType255.
function encoderDictionary(id, quirks, rangeCounts) {
    const eds = new Eds();
    communication(eds, id, { deviceType: 0x00020196, vendorId: 0x0000CAFE, productCode: 0x406, heartbeatConsumer: false });
    const options = { rtrFixed: false, maxType: quirks.noType255 ? 254 : 255 };
    for (let n = 1; n <= quirks.encoderTpdos; ++n)
        pdo(eds, true, n, 0x80 + 0x100 * n + id, n === 1 ? [map(0x6004, 0, 32)] : [], options);
    variable(eds, 0x6000, 'Operating parameters', DataType.UNSIGNED16, RW, 0);
    variable(eds, 0x6001, 'Measuring units per revolution', DataType.UNSIGNED32, RW, 4096);
    variable(eds, 0x6002, 'Total measuring range in measuring units', DataType.UNSIGNED32, RW, rangeCounts);
    variable(eds, 0x6004, 'Position value', DataType.UNSIGNED32, RO, 0);
    return eds;
}

module.exports = { driveDictionary, encoderDictionary };
