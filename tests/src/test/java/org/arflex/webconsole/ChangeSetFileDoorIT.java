package org.arflex.webconsole;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.extension.RegisterExtension;

/** Issue 30 finding 9 on the real console ({@link ChangeSetFileDoor}): the door is shut, the control open. */
class ChangeSetFileDoorIT {
    @RegisterExtension
    static final ConsoleFixture FX = ConsoleFixture.runtime("changeset-file-door").started("sample-counter");

    @Test
    void anUpdateFromAFileOutsideTheStagingFoldersIsRefusedWithoutItsDigest() {
        ChangeSetFileDoor.Result r = ChangeSetFileDoor.tryOn(FX.rt(),
                org.arflex.it.Components.jar("sample-counter").toUri().toString());
        assertEquals(0, r.succeeded(), r.detail());
        assertTrue(r.controlSeen(), "control: a jar inside a staging folder gets the DRCR's answer with its SHA-256");
    }
}
